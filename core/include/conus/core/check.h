// Invariants the code relies on, checked in Debug builds (NDEBUG unset) and compiled out of
// Release ones, as pbrt's DCHECK: CONUS_DCHECK(condition) and CONUS_DCHECK_EQ/_LE/_LT/_GE(a, b),
// which print both values. A failed check is a bug in CoNUS, not bad input (bad input throws
// conus::Error with a message for the user): it prints the file, the line, the condition and the
// values to stderr and aborts. The arguments are not evaluated in Release builds, so a check
// must have no effect the code needs.
#pragma once

#include <sstream>
#include <string>

namespace conus::detail {

[[noreturn]] void checkFailed(const char* file, int line, const char* condition, const std::string& values);

template <typename A, typename B>
std::string checkValues(const A& a, const B& b) {
    std::ostringstream s;
    s << a << " vs " << b;
    return s.str();
}

}  // namespace conus::detail

#ifdef NDEBUG
#define CONUS_DCHECK(condition) static_cast<void>(0)
#define CONUS_DCHECK_OP(op, a, b) static_cast<void>(0)
#else
#define CONUS_DCHECK(condition) \
    (static_cast<bool>(condition) ? static_cast<void>(0) : ::conus::detail::checkFailed(__FILE__, __LINE__, #condition, {}))
#define CONUS_DCHECK_OP(op, a, b)                                                                              \
    do {                                                                                                     \
        const auto& conusCheckA_ = (a);                                                                      \
        const auto& conusCheckB_ = (b);                                                                      \
        if (!(conusCheckA_ op conusCheckB_))                                                                 \
            ::conus::detail::checkFailed(__FILE__, __LINE__, #a " " #op " " #b,                              \
                                         ::conus::detail::checkValues(conusCheckA_, conusCheckB_));          \
    } while (false)
#endif
#define CONUS_DCHECK_EQ(a, b) CONUS_DCHECK_OP(==, a, b)
#define CONUS_DCHECK_LE(a, b) CONUS_DCHECK_OP(<=, a, b)
#define CONUS_DCHECK_LT(a, b) CONUS_DCHECK_OP(<, a, b)
#define CONUS_DCHECK_GE(a, b) CONUS_DCHECK_OP(>=, a, b)
