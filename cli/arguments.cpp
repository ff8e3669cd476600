#include "arguments.h"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "conus/core/error.h"

namespace conus::cli {
namespace {

[[noreturn]] void invalid(const std::string& what) { throw Error(ErrorCode::InvalidArgument, what); }

std::vector<double> parseNumbers(const std::string& text, char separator) {
    std::vector<double> values;
    std::stringstream stream(text);
    std::string item;
    while (std::getline(stream, item, separator)) {
        char* end = nullptr;
        const double value = std::strtod(item.c_str(), &end);
        if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(value))
            invalid("'" + text + "': '" + item + "' is not a number");
        values.push_back(value);
    }
    return values;
}

}  // namespace

Size parseSize(const std::string& text) {
    const auto values = parseNumbers(text, 'x');
    if (values.size() != 2 || text.back() == 'x') invalid("size '" + text + "' is not of the form WxH");
    for (double v : values)
        if (v != std::floor(v) || v < 1 || v > kMaxImageSide)
            invalid("size '" + text + "': each side must be a whole number in [1, 65536]");
    return {static_cast<int>(values[0]), static_cast<int>(values[1])};
}

codec::View parseView(const std::string& text) {
    const auto values = parseNumbers(text, ',');
    if (values.size() != 4) invalid("view '" + text + "' is not of the form u0,v0,u1,v1");
    const codec::View view{values[0], values[1], values[2], values[3]};
    codec::checkView(view, "'" + text + "'");
    return view;
}

CLI::Validator finiteRange(double low, double high, bool lowIncluded) {
    std::ostringstream range;
    range << (lowIncluded ? "[" : "(") << low << ", " << high << ")";
    const std::string description = "a finite number in " + range.str();
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            const bool aboveLow = lowIncluded ? value >= low : value > low;
            if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value) || !aboveLow || !(value < high))
                return "'" + text + "' is not " + description;
            return {};
        },
        description);
}

CameraText parseCamera(const std::string& text) {
    const auto v = parseNumbers(text, ',');
    if (v.size() != 7 || text.back() == ',') invalid("camera '" + text + "' needs 7 values x,y,z,lx,ly,lz,fovDeg");
    if (!(v[6] > 0 && v[6] < 180)) invalid("camera '" + text + "': the field of view must lie in (0, 180) degrees");
    return {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, v[6]};
}

glm::dvec3 parseVector3(const std::string& text, const std::string& what) {
    const auto v = parseNumbers(text, ',');
    if (v.size() != 3 || text.back() == ',') invalid(what + " '" + text + "' needs 3 values x,y,z");
    return {v[0], v[1], v[2]};
}

CLI::Option* addCompressionOption(CLI::App& command, std::string& compression) {
    return command.add_option("--compression", compression, "how the file's pixels are compressed (dwaa: lossy)")
        ->default_val(enumName(format::Compression::Zip))
        ->check(CLI::IsMember(enumNames<format::Compression>()));
}

void addAllowDirOption(CLI::App& command, std::vector<std::string>& dirs) {
    command.add_option("--allow-dir", dirs,
                       "a folder the files a scene file names (buffers, material libraries, data files) may also lie in; "
                       "by default only the scene file's own folder (repeatable)")
        ->check(CLI::ExistingDirectory);
}

}  // namespace conus::cli
