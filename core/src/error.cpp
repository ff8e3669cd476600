#include "conus/core/error.h"

#include <cmath>
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

std::string lossText(double db, const char* lose, const char* gain, int decimals) {
    char text[64];
    std::snprintf(text, sizeof text, "%s %.*f dB", db < 0 ? gain : lose, decimals, std::abs(db));
    return text;
}

}  // namespace conus
