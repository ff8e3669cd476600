#include "conus/core/check.h"

#include <cstdio>
#include <cstdlib>

namespace conus::detail {

void checkFailed(const char* file, int line, const char* condition, const std::string& values) {
    std::fprintf(stderr, "%s:%d: CoNUS invariant failed: %s%s%s\n", file, line, condition, values.empty() ? "" : ": ",
                 values.c_str());
    std::abort();
}

}  // namespace conus::detail
