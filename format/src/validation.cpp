// ValidationReport helpers and the toString functions of the header model.
#include <algorithm>

#include "conus/format/container.h"
#include "conus/format/validation.h"

namespace conus::format {

bool ValidationReport::violates(int rule) const {
    return std::any_of(issues.begin(), issues.end(), [rule](const Issue& i) { return i.rule == rule; });
}

void ValidationReport::add(int rule, std::string message) {
    std::replace_if(message.begin(), message.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    issues.push_back({rule, std::move(message)});
}

std::string ValidationReport::str() const {
    std::string out;
    for (const Issue& issue : issues) {
        if (!out.empty()) out += "; ";
        if (issue.rule == 0) {
            out += "error: ";
        } else {
            out += 'V';
            out += std::to_string(issue.rule);
            out += ": ";
        }
        out += issue.message;
    }
    return out;
}

const char* toString(PixelType t) {
    switch (t) {
        case PixelType::Half: return "half";
        case PixelType::Float: return "float";
    }
    return "unknown";
}

const char* toString(Compression c) {
    switch (c) {
        case Compression::None: return "none";
        case Compression::Zip: return "zip";
        case Compression::Piz: return "piz";
        case Compression::Dwaa: return "dwaa";
    }
    return "unknown";
}

const char* toString(DataKind k) {
    switch (k) {
        case DataKind::Image: return "image";
        case DataKind::HeightField: return "heightfield";
        case DataKind::DepthImage: return "depthimage";
    }
    return "unknown";
}

const char* toString(DepthKind k) {
    switch (k) {
        case DepthKind::None: return "none";
        case DepthKind::CameraDepth: return "cameraDepth";
        case DepthKind::Height: return "height";
    }
    return "unknown";
}

}  // namespace conus::format
