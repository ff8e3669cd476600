#include <gtest/gtest.h>

#include "conus/core/error.h"

TEST(Error, MessagesAreAlwaysOneLine) {
    const conus::Error e(conus::ErrorCode::Io, "cannot read x.tif: first line\nsecond line\r\n");
    EXPECT_STREQ(e.what(), "cannot read x.tif: first line; second line");
    EXPECT_EQ(e.code(), conus::ErrorCode::Io);
    EXPECT_EQ(conus::oneLine("a\n\nb"), "a; ; b");
    EXPECT_EQ(conus::oneLine("plain"), "plain");
}

TEST(Error, ALossBelowZeroIsSaidAsAGain) {
    EXPECT_EQ(conus::lossText(1.5, "loses", "gains", 2), "loses 1.50 dB");
    EXPECT_EQ(conus::lossText(-0.94, "loses", "gains", 1), "gains 0.9 dB");
    EXPECT_EQ(conus::lossText(-3.25, "lose", "gain", 1), "gain 3.2 dB");  // printf rounds half to even here
    EXPECT_EQ(conus::lossText(0.0, "loses", "gains", 1), "loses 0.0 dB");
}
