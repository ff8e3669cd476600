#include "conus/core/error.h"

#include <cstdio>

namespace conus {

std::string oneLine(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        if (c == '\r') continue;
        if (c == '\n') out += "; ";
        else out += c;
    }
    return out;
}

std::string numberText(double value, int significantDigits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", significantDigits, value);
    return buf;
}

}  // namespace conus
