// What a test asks of a call that must fail: the conus::Error code it throws.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "conus/core/error.h"

namespace conus::test {

// The code of the conus::Error that `fn` throws, its message in *message when given. A call that
// throws nothing fails the test (the code returned then is ErrorCode::Io, which no caller expects
// alone).
template <class Fn>
ErrorCode codeOf(Fn&& fn, std::string* message = nullptr) {
    try {
        fn();
    } catch (const Error& e) {
        if (message) *message = e.what();
        return e.code();
    }
    ADD_FAILURE() << "no conus::Error thrown";
    return ErrorCode::Io;
}

}  // namespace conus::test
