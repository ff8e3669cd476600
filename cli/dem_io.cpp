// DEM readers: the .npy header parser and the .npz (zip) archive access live here, the only
// files of cli/ that touch libzip.
#include "dem_io.h"

#include <zip.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <regex>
#include <vector>

#include "conus/codec/heightfield.h"
#include "conus/core/error.h"
#include "image_files.h"

namespace conus::cli {
namespace {

// One parsed .npy array, values converted to double.
struct NpyArray {
    std::vector<std::int64_t> shape;
    std::vector<double> values;
    std::string dtype;
};

template <typename T>
void convert(const unsigned char* data, std::size_t count, bool swap, std::vector<double>& out) {
    out.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        unsigned char bytes[sizeof(T)];
        std::memcpy(bytes, data + i * sizeof(T), sizeof(T));
        if (swap) std::reverse(bytes, bytes + sizeof(T));
        T value;
        std::memcpy(&value, bytes, sizeof(T));
        out[i] = static_cast<double>(value);
    }
}

// Format: magic "\x93NUMPY", major, minor, header length (2 bytes in v1, 4 in v2/3), then a Python
// dict literal {'descr': '<f8', 'fortran_order': False, 'shape': (344, 403), }, then C-order data.
NpyArray parseNpy(const std::vector<unsigned char>& bytes, const std::string& what) {
    const auto fail = [&](const std::string& why) { return Error(ErrorCode::InvalidArgument, what + ": " + why); };
    if (bytes.size() < 10 || std::memcmp(bytes.data(), "\x93NUMPY", 6) != 0) throw fail("not a NumPy .npy array");
    const int major = bytes[6];
    std::size_t headerLength = 0, offset = 0;
    if (major == 1) {
        headerLength = bytes[8] | (bytes[9] << 8);
        offset = 10;
    } else if (major == 2 || major == 3) {
        if (bytes.size() < 12) throw fail("truncated header");
        headerLength = bytes[8] | (bytes[9] << 8) | (bytes[10] << 16) | (std::size_t(bytes[11]) << 24);
        offset = 12;
    } else {
        throw fail(".npy version " + std::to_string(major) + " is not supported");
    }
    if (offset + headerLength > bytes.size()) throw fail("header runs past the end of the data");
    const std::string header(reinterpret_cast<const char*>(bytes.data() + offset), headerLength);
    std::smatch m;
    NpyArray a;
    if (!std::regex_search(header, m, std::regex("'descr'\\s*:\\s*'([^']*)'"))) throw fail("no dtype in the header");
    a.dtype = m[1];
    if (std::regex_search(header, m, std::regex("'fortran_order'\\s*:\\s*True")))
        throw fail("Fortran-ordered arrays are not supported");
    if (!std::regex_search(header, m, std::regex("'shape'\\s*:\\s*\\(([^)]*)\\)"))) throw fail("no shape in the header");
    const std::string shape = m[1];
    std::int64_t count = 1;
    const std::regex number("\\d+");
    for (std::sregex_iterator it(shape.begin(), shape.end(), number), end; it != end; ++it) {
        const std::int64_t n = std::stoll(it->str());
        if (n <= 0 || n > format::kMaxImageSide) throw fail("dimension " + it->str() + " is outside [1, 65536]");
        a.shape.push_back(n);
        count *= n;
        if (count > format::kMaxImagePixels) throw fail("more than 2^30 values");
    }
    const std::string& d = a.dtype;
    if (d.size() < 3) throw fail("dtype '" + d + "' is not supported");
    const bool swap = d[0] == '>';  // this machine is little-endian ('<', '|' and '=' need nothing)
    const std::string kind = d.substr(1);
    static const std::map<std::string, std::size_t> kSizes = {{"f8", 8}, {"f4", 4}, {"i2", 2}, {"u2", 2}, {"i4", 4},
                                                              {"u4", 4}, {"i8", 8}, {"u1", 1}, {"i1", 1}};
    const auto size = kSizes.find(kind);
    if (size == kSizes.end()) throw fail("dtype '" + d + "' is not supported (f4, f8, i1/u1, i2/u2, i4/u4, i8)");
    const std::size_t dataOffset = offset + headerLength;
    if (bytes.size() - dataOffset < static_cast<std::size_t>(count) * size->second)
        throw fail("holds " + std::to_string(bytes.size() - dataOffset) + " data bytes, the shape needs " +
                   std::to_string(count * size->second));
    const unsigned char* data = bytes.data() + dataOffset;
    if (kind == "f8") convert<double>(data, count, swap, a.values);
    else if (kind == "f4") convert<float>(data, count, swap, a.values);
    else if (kind == "i2") convert<std::int16_t>(data, count, swap, a.values);
    else if (kind == "u2") convert<std::uint16_t>(data, count, swap, a.values);
    else if (kind == "i4") convert<std::int32_t>(data, count, swap, a.values);
    else if (kind == "u4") convert<std::uint32_t>(data, count, swap, a.values);
    else if (kind == "i8") convert<std::int64_t>(data, count, swap, a.values);
    else if (kind == "u1") convert<std::uint8_t>(data, count, swap, a.values);
    else convert<std::int8_t>(data, count, swap, a.values);
    return a;
}

// Every member of a .npz archive, by name without ".npy".
std::map<std::string, NpyArray> readNpz(const std::string& path) {
    int error = 0;
    std::unique_ptr<zip_t, decltype(&zip_close)> archive(zip_open(path.c_str(), ZIP_RDONLY, &error), &zip_close);
    if (!archive) throw Error(ErrorCode::Io, path + ": cannot open as a .npz (zip) archive (libzip error " +
                                                 std::to_string(error) + ")");
    std::map<std::string, NpyArray> arrays;
    const zip_int64_t entries = zip_get_num_entries(archive.get(), 0);
    for (zip_int64_t i = 0; i < entries; ++i) {
        zip_stat_t stat;
        if (zip_stat_index(archive.get(), i, 0, &stat) != 0 || !(stat.valid & ZIP_STAT_SIZE)) continue;
        std::string name = stat.name;
        if (name.size() < 4 || name.substr(name.size() - 4) != ".npy") continue;
        if (stat.size > (std::uint64_t(1) << 34))
            throw Error(ErrorCode::LimitExceeded, path + ": member " + name + " is too large");
        std::unique_ptr<zip_file_t, decltype(&zip_fclose)> file(zip_fopen_index(archive.get(), i, 0), &zip_fclose);
        if (!file) throw Error(ErrorCode::Io, path + ": cannot read member " + name);
        std::vector<unsigned char> bytes(stat.size);
        if (zip_fread(file.get(), bytes.data(), stat.size) != static_cast<zip_int64_t>(stat.size))
            throw Error(ErrorCode::Io, path + ": member " + name + " is truncated");
        name.resize(name.size() - 4);
        arrays.emplace(name, parseNpy(bytes, path + ":" + name));
    }
    return arrays;
}

format::Image toHeights(const NpyArray& a, double scale, const std::string& what) {
    if (a.shape.size() != 2) throw Error(ErrorCode::InvalidArgument, what + ": not a 2-D array");
    format::Image im = format::makeImage(static_cast<int>(a.shape[1]), static_cast<int>(a.shape[0]), {"Z"});
    for (std::size_t i = 0; i < a.values.size(); ++i) im.pixels[i] = static_cast<float>(a.values[i] * scale);
    return im;
}

bool endsWith(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size()) return false;
    std::string tail = s.substr(s.size() - suffix.size());
    for (char& c : tail) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return tail == suffix;
}

}  // namespace

Dem readDem(const std::string& source, double heightScale) {
    if (!(std::isfinite(heightScale) && heightScale != 0.0))
        throw Error(ErrorCode::InvalidArgument, "height scale " + std::to_string(heightScale) + " must be finite and non-zero");
    Dem dem;
    std::smatch m;
    if (std::regex_match(source, m, std::regex("procedural(?::(\\d+))?(?::(\\d+))?"))) {
        codec::TerrainOptions options;
        if (m[1].matched) options.width = options.height = std::stoi(m[1].str().substr(0, 6));
        if (m[2].matched) options.seed = static_cast<std::uint32_t>(std::stoul(m[2].str().substr(0, 9)));
        dem.heights = codec::generateTerrain(options);
        if (heightScale != 1.0)
            for (float& h : dem.heights.pixels) h = static_cast<float>(h * heightScale);
        dem.description = "procedural terrain " + std::to_string(options.width) + "x" + std::to_string(options.height) +
                          " seed " + std::to_string(options.seed);
        return dem;
    }
    if (endsWith(source, ".npz")) {
        const auto arrays = readNpz(source);
        auto it = arrays.find("elevation");
        if (it == arrays.end())
            it = std::find_if(arrays.begin(), arrays.end(), [](const auto& a) { return a.second.shape.size() == 2; });
        if (it == arrays.end()) throw Error(ErrorCode::InvalidArgument, source + ": holds no 2-D array");
        dem.heights = toHeights(it->second, heightScale, source + ":" + it->first);
        // matplotlib's sample stores its spacing in degrees of longitude / latitude.
        const auto scalar = [&](const char* name) {
            const auto s = arrays.find(name);
            return s != arrays.end() && s->second.values.size() == 1 ? s->second.values[0] : std::nan("");
        };
        const double dx = scalar("dx"), dy = scalar("dy"), y0 = scalar("ymin"), y1 = scalar("ymax");
        if (std::isfinite(dx) && std::isfinite(dy) && dx > 0 && dy > 0) {
            if (dx < 0.1 && std::isfinite(y0) && std::isfinite(y1) && std::abs(y0) <= 90) {
                constexpr double kMetresPerDegree = 111320.0;
                const double latitude = 0.5 * (y0 + y1) * 3.14159265358979323846 / 180.0;
                dem.cellMetres = {dx * kMetresPerDegree * std::cos(latitude), dy * kMetresPerDegree};
            } else {
                dem.cellMetres = {dx, dy};
            }
        }
        dem.description = source + " " + it->first + " " + std::to_string(dem.heights.width) + "x" +
                          std::to_string(dem.heights.height) + " " + it->second.dtype;
        return dem;
    }
    if (endsWith(source, ".npy")) {
        std::ifstream in(source, std::ios::binary);
        if (!in) throw Error(ErrorCode::Io, source + ": cannot open");
        const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const NpyArray a = parseNpy(bytes, source);
        dem.heights = toHeights(a, heightScale, source);
        dem.description = source + " " + std::to_string(dem.heights.width) + "x" + std::to_string(dem.heights.height) +
                          " " + a.dtype;
        return dem;
    }
    const format::Image image = readData(source);
    int channel = image.channelIndex("Z");
    if (channel < 0) channel = image.channelIndex("Y");
    if (channel < 0) channel = 0;  // a grey or RGB image: its first channel
    dem.heights = format::makeImage(image.width, image.height, {"Z"});
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            dem.heights.at(x, y) = static_cast<float>(image.at(x, y, channel) * heightScale);
    dem.description = source + " " + std::to_string(image.width) + "x" + std::to_string(image.height) + " channel " +
                      image.channels[channel];
    return dem;
}

}  // namespace conus::cli
