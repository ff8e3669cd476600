#include <gtest/gtest.h>

#include "conus/core/error.h"

TEST(Error, MessagesAreAlwaysOneLine) {
    const conus::Error e(conus::ErrorCode::Io, "cannot read x.tif: first line\nsecond line\r\n");
    EXPECT_STREQ(e.what(), "cannot read x.tif: first line; second line");
    EXPECT_EQ(e.code(), conus::ErrorCode::Io);
    EXPECT_EQ(conus::oneLine("a\n\nb"), "a; ; b");
    EXPECT_EQ(conus::oneLine("plain"), "plain");
}
