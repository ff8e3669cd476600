// DEM readers: the .npy header parser and the .npz (zip) archive access live here, the only
// file that touches libzip.
#include "conus/sceneio/dem_file.h"

#include <zip.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/imageio/image_file.h"

namespace conus::sceneio {
namespace {

// A .npy header never needs more than this (NumPy writes a few hundred bytes); a larger one is
// refused before anything is read past it.
constexpr std::size_t kMaxNpyHeaderBytes = 64 * 1024;
// Deflate expands at most 1032 times (a 258-byte match in 2 bits): an .npz member claiming more
// is lying about its size.
constexpr std::uint64_t kMaxDeflateRatio = 1032;

// One parsed .npy header: dtype, shape and where the C-order data starts.
struct NpyHeader {
    std::vector<std::int64_t> shape;
    std::string dtype;
    std::string kind;  // dtype without its byte-order character: f8, i2, ...
    bool swap = false;
    std::size_t itemSize = 0;
    std::size_t dataOffset = 0;
    std::int64_t count = 1;
    std::uint64_t bytes() const { return dataOffset + std::uint64_t(count) * itemSize; }
};

// One array: its header and the file's bytes (the data starts at header.dataOffset).
struct NpyArray {
    NpyHeader header;
    std::vector<unsigned char> bytes;
};

// A file that does not hold what it says: a failure (exit 1), not a usage error.
[[noreturn]] void fail(const std::string& what, const std::string& why) {
    throw Error(ErrorCode::Corrupt, what + ": " + why);
}

// "4", " 4", "4L" -> 4; anything else (a sign, a fraction, too many digits) is refused.
std::int64_t dimension(std::string item, const std::string& shape, const std::string& what) {
    const auto first = item.find_first_not_of(" \t"), last = item.find_last_not_of(" \t");
    item = first == std::string::npos ? std::string() : item.substr(first, last - first + 1);
    if (!item.empty() && item.back() == 'L') item.pop_back();  // Python 2 longs
    if (item.empty() || item.size() > 9 || item.find_first_not_of("0123456789") != std::string::npos)
        fail(what, "shape (" + shape + ") has a dimension '" + item + "' that is not a whole number in [1, " +
                       std::to_string(kMaxImageSide) + "]");
    const std::int64_t n = std::stoll(item);
    if (n < 1 || n > kMaxImageSide)
        fail(what, "shape (" + shape + ") has a dimension " + item + " outside [1, " + std::to_string(kMaxImageSide) + "]");
    return n;
}

// The header's dict literal, {'descr': '<f8', 'fortran_order': False, 'shape': (344, 403), },
// read by hand in one pass: keys and string values in single or double quotes, a tuple of
// numbers, or a word (True, False). Each value has a length limit far beyond what NumPy writes,
// so that neither the scan nor a message grows with a hostile header; keys NumPy does not write
// are passed over.
struct NpyDict {
    std::optional<std::string> descr, shape;  // the shape without its parentheses
    std::string fortranOrder;
};

NpyDict parseNpyDict(std::string_view text, const std::string& what) {
    constexpr std::size_t kMaxKey = 32, kMaxString = 32, kMaxShape = 256, kMaxWord = 8;
    std::size_t at = 0;
    const auto skipSpace = [&] {
        while (at < text.size() && (text[at] == ' ' || text[at] == '\t' || text[at] == '\n' || text[at] == '\r')) ++at;
    };
    const auto broken = [&](const std::string& why) { fail(what, "the header is not a NumPy dict: " + why); };
    // Characters up to `end` (exclusive), at most `limit` of them; `at` ends past `end`.
    const auto until = [&](char end, std::size_t limit, const char* field) {
        const std::size_t from = at;
        while (at < text.size() && text[at] != end) {
            if (at - from >= limit)
                fail(what, std::string("the header's ") + field + " is longer than " + std::to_string(limit) + " characters");
            ++at;
        }
        if (at >= text.size()) broken(std::string("its ") + field + " does not end");
        return std::string(text.substr(from, at++ - from));
    };
    NpyDict dict;
    skipSpace();
    if (at >= text.size() || text[at++] != '{') broken("it does not start with '{'");
    for (;;) {
        skipSpace();
        if (at < text.size() && text[at] == '}') break;
        if (at >= text.size() || (text[at] != '\'' && text[at] != '"')) broken("a key is not a quoted string");
        const std::string key = until(text[at++], kMaxKey, "key");
        skipSpace();
        if (at >= text.size() || text[at++] != ':') broken("no ':' after a key");
        skipSpace();
        if (at >= text.size()) broken("a value is missing");
        if (text[at] == '\'' || text[at] == '"') {
            std::string value = until(text[at++], kMaxString, "dtype");
            if (key == "descr") dict.descr = std::move(value);
        } else if (text[at] == '(') {
            ++at;
            std::string value = until(')', kMaxShape, "shape");
            if (key == "shape") dict.shape = std::move(value);
        } else {
            const std::size_t from = at;
            while (at < text.size() && std::isalpha(static_cast<unsigned char>(text[at])))
                if (++at - from > kMaxWord) broken("a word value is too long");
            if (at == from) broken("a value is neither a string, a tuple nor a word");
            if (key == "fortran_order") dict.fortranOrder = std::string(text.substr(from, at - from));
        }
        skipSpace();
        if (at < text.size() && text[at] == ',') {
            ++at;
            continue;
        }
        if (at < text.size() && text[at] == '}') break;
        broken("no ',' or '}' after a value");
    }
    return dict;
}

// Format: magic "\x93NUMPY", major, minor, header length (2 bytes in v1, 4 in v2/3), then a Python
// dict literal {'descr': '<f8', 'fortran_order': False, 'shape': (344, 403), }, then C-order data.
// `available` bytes of the file are at `data`; the header must lie within them.
NpyHeader parseNpyHeader(const unsigned char* data, std::size_t available, const std::string& what) {
    if (available < 10 || std::memcmp(data, "\x93NUMPY", 6) != 0) fail(what, "not a NumPy .npy array");
    const int major = data[6];
    std::size_t headerLength = 0, offset = 0;
    if (major == 1) {
        headerLength = data[8] | (data[9] << 8);
        offset = 10;
    } else if (major == 2 || major == 3) {
        if (available < 12) fail(what, "truncated header");
        headerLength = data[8] | (data[9] << 8) | (data[10] << 16) | (std::size_t(data[11]) << 24);
        offset = 12;
    } else {
        fail(what, ".npy version " + std::to_string(major) + " is not supported");
    }
    if (headerLength > kMaxNpyHeaderBytes)
        fail(what, "header of " + std::to_string(headerLength) + " bytes, more than " + std::to_string(kMaxNpyHeaderBytes));
    if (offset + headerLength > available) fail(what, "header runs past the end of the data");
    const NpyDict dict = parseNpyDict(std::string_view(reinterpret_cast<const char*>(data + offset), headerLength), what);
    NpyHeader h;
    if (!dict.descr) fail(what, "no dtype in the header");
    h.dtype = *dict.descr;
    if (dict.fortranOrder == "True") fail(what, "Fortran-ordered arrays are not supported");
    if (!dict.shape) fail(what, "no shape in the header");
    const std::string shape = *dict.shape;
    std::stringstream items(shape);
    for (std::string item; std::getline(items, item, ',');) {
        if (item.find_first_not_of(" \t") == std::string::npos && items.eof()) break;  // "(5,)": the trailing comma
        h.shape.push_back(dimension(item, shape, what));
        h.count *= h.shape.back();  // each factor <= 2^16 and the product is checked at each step: no overflow
        if (h.count > kMaxDemSamples)
            throw Error(ErrorCode::LimitExceeded, what + ": shape (" + shape + ") holds more than the limit of " +
                                                      std::to_string(kMaxDemSamples) + " height samples");
    }
    const std::string& d = h.dtype;
    if (d.size() < 3) fail(what, "dtype '" + d + "' is not supported");
    h.swap = d[0] == '>';  // this machine is little-endian ('<', '|' and '=' need nothing)
    h.kind = d.substr(1);
    static const std::map<std::string, std::size_t> kSizes = {{"f8", 8}, {"f4", 4}, {"i2", 2}, {"u2", 2}, {"i4", 4},
                                                              {"u4", 4}, {"i8", 8}, {"u1", 1}, {"i1", 1}};
    const auto size = kSizes.find(h.kind);
    if (size == kSizes.end()) fail(what, "dtype '" + d + "' is not supported (f4, f8, i1/u1, i2/u2, i4/u4, i8)");
    h.itemSize = size->second;
    h.dataOffset = offset + headerLength;
    return h;
}

// An array from a stream of `size` bytes, read through read(buffer, n) (which throws on a short
// read): the header first, then exactly the bytes its shape needs, so memory follows the shape
// only once the stream is known to be long enough for it.
template <class Read>
NpyArray readNpy(std::uint64_t size, Read read, const std::string& what) {
    NpyArray a;
    a.bytes.resize(std::min<std::uint64_t>(size, kMaxNpyHeaderBytes + 12));
    read(a.bytes.data(), a.bytes.size());
    a.header = parseNpyHeader(a.bytes.data(), a.bytes.size(), what);
    if (size < a.header.bytes())
        fail(what, "holds " + std::to_string(size) + " bytes, the shape needs " + std::to_string(a.header.bytes()));
    const std::size_t have = a.bytes.size();
    a.bytes.resize(a.header.bytes());
    if (a.bytes.size() > have) read(a.bytes.data() + have, a.bytes.size() - have);
    return a;
}

template <typename T, typename Out>
void convert(const unsigned char* data, std::size_t count, bool swap, double scale, Out* out) {
    for (std::size_t i = 0; i < count; ++i) {
        unsigned char bytes[sizeof(T)];
        std::memcpy(bytes, data + i * sizeof(T), sizeof(T));
        if (swap) std::reverse(bytes, bytes + sizeof(T));
        T value;
        std::memcpy(&value, bytes, sizeof(T));
        out[i] = static_cast<Out>(static_cast<double>(value) * scale);
    }
}

// The first `count` values of the array, times scale.
template <typename Out>
void values(const NpyArray& a, std::size_t count, double scale, Out* out) {
    const unsigned char* data = a.bytes.data() + a.header.dataOffset;
    const std::string& kind = a.header.kind;
    const bool swap = a.header.swap;
    if (kind == "f8") convert<double>(data, count, swap, scale, out);
    else if (kind == "f4") convert<float>(data, count, swap, scale, out);
    else if (kind == "i2") convert<std::int16_t>(data, count, swap, scale, out);
    else if (kind == "u2") convert<std::uint16_t>(data, count, swap, scale, out);
    else if (kind == "i4") convert<std::int32_t>(data, count, swap, scale, out);
    else if (kind == "u4") convert<std::uint32_t>(data, count, swap, scale, out);
    else if (kind == "i8") convert<std::int64_t>(data, count, swap, scale, out);
    else if (kind == "u1") convert<std::uint8_t>(data, count, swap, scale, out);
    else convert<std::int8_t>(data, count, swap, scale, out);
}

// A one-value array's value (matplotlib's DEMs store their spacing so), else NaN.
double scalar(const NpyArray& a) {
    if (a.header.count != 1) return std::nan("");
    double v = 0;
    values(a, 1, 1.0, &v);
    return v;
}

// A FIFO or a device (/dev/zero) never ends: DEM files are read only when they are regular files.
void requireRegularFile(const std::string& path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status))
        throw Error(ErrorCode::Io, path + ": cannot open (" + (ec ? ec.message() : std::string("no such file")) + ")");
    if (!std::filesystem::is_regular_file(status)) throw Error(ErrorCode::Io, path + ": not a regular file");
}

// A .npz archive's .npy members, read one at a time and only when asked: the elevation model and
// a few scalars are all a DEM needs, so a large member nobody uses is never inflated. Each
// member's claimed size is checked against its compressed size before any of it is read, and a
// member is inflated whole only once its own header (the first bytes, inflated alone) has passed
// the limits.
class Npz {
public:
    explicit Npz(const std::string& path) : m_path(path), m_archive(nullptr, &zip_close) {
        m_archiveSize = std::filesystem::file_size(path);
        int error = 0;
        m_archive.reset(zip_open(path.c_str(), ZIP_RDONLY, &error));
        if (!m_archive) throw Error(ErrorCode::Io, path + ": cannot open as a .npz (zip) archive (libzip error " +
                                                       std::to_string(error) + ")");
        const zip_int64_t entries = zip_get_num_entries(m_archive.get(), 0);
        for (zip_int64_t i = 0; i < entries; ++i) {
            zip_stat_t stat;
            zip_stat_init(&stat);
            constexpr zip_uint64_t kNeeded = ZIP_STAT_NAME | ZIP_STAT_SIZE | ZIP_STAT_COMP_SIZE | ZIP_STAT_COMP_METHOD;
            if (zip_stat_index(m_archive.get(), i, 0, &stat) != 0 || (stat.valid & kNeeded) != kNeeded) continue;
            std::string name = stat.name;
            if (name.size() < 4 || name.substr(name.size() - 4) != ".npy") continue;
            name.resize(name.size() - 4);
            m_members.emplace(name, stat);  // the first of a repeated name, as before
        }
    }

    // Member names without ".npy", in name order.
    std::vector<std::string> names() const {
        std::vector<std::string> out;
        for (const auto& [name, stat] : m_members) out.push_back(name);
        return out;
    }
    bool has(const std::string& name) const { return m_members.count(name) > 0; }

    // The member's header alone (its bytes hold the header only).
    NpyArray header(const std::string& name) { return read(name, true); }
    // The whole member.
    NpyArray array(const std::string& name) { return read(name, false); }

private:
    NpyArray read(const std::string& name, bool headerOnly) {
        const zip_stat_t& stat = m_members.at(name);
        const std::string what = m_path + ":" + name + ".npy";
        if (stat.comp_method != ZIP_CM_STORE && stat.comp_method != ZIP_CM_DEFLATE)
            throw Error(ErrorCode::Unsupported, what + ": compression method " + std::to_string(stat.comp_method) +
                                                    " is not supported (stored or deflate, as NumPy writes)");
        const std::uint64_t ratio = stat.comp_method == ZIP_CM_STORE ? 1 : kMaxDeflateRatio;
        if (stat.comp_size > m_archiveSize || stat.size > stat.comp_size * ratio + 64)
            throw Error(ErrorCode::Corrupt, what + ": claims " + std::to_string(stat.size) + " bytes from " +
                                                std::to_string(stat.comp_size) + " compressed bytes in a " +
                                                std::to_string(m_archiveSize) + "-byte archive; " +
                                                (ratio == 1 ? std::string("stored data cannot expand")
                                                            : "deflate expands at most " + std::to_string(ratio) + " times"));
        std::unique_ptr<zip_file_t, decltype(&zip_fclose)> file(zip_fopen_index(m_archive.get(), stat.index, 0), &zip_fclose);
        if (!file) throw Error(ErrorCode::Io, what + ": cannot read the member");
        const auto readBytes = [&](unsigned char* buffer, std::size_t n) {
            if (zip_fread(file.get(), buffer, n) != static_cast<zip_int64_t>(n))
                throw Error(ErrorCode::Io, what + ": the member is truncated or damaged");
        };
        if (!headerOnly) {
            // What the members read may inflate to in all: the largest elevation model as int64
            // or float64, and headers.
            constexpr std::uint64_t kMaxInflatedBytes = std::uint64_t(kMaxDemSamples) * 8 + 16 * (kMaxNpyHeaderBytes + 12);
            m_inflated += stat.size;
            if (m_inflated > kMaxInflatedBytes)
                throw Error(ErrorCode::LimitExceeded, what + ": the arrays read inflate to more than " +
                                                          std::to_string(kMaxInflatedBytes) + " bytes, the limit for " +
                                                          std::to_string(kMaxDemSamples) + " height samples");
            return readNpy(stat.size, readBytes, what);
        }
        NpyArray a;
        a.bytes.resize(std::min<std::uint64_t>(stat.size, kMaxNpyHeaderBytes + 12));
        readBytes(a.bytes.data(), a.bytes.size());
        a.header = parseNpyHeader(a.bytes.data(), a.bytes.size(), what);
        return a;
    }

    std::string m_path;
    std::uintmax_t m_archiveSize = 0;
    std::unique_ptr<zip_t, decltype(&zip_close)> m_archive;
    std::map<std::string, zip_stat_t> m_members;
    std::uint64_t m_inflated = 0;
};

// Every height a file gives is a finite number (NaN or an overflow past float is bad data).
void checkHeights(const Image& heights, const std::string& what) {
    for (std::size_t i = 0; i < heights.pixels.size(); ++i)
        if (!std::isfinite(heights.pixels[i]))
            throw Error(ErrorCode::Corrupt, what + ": height at (" + std::to_string(i % heights.width) + ", " +
                                                std::to_string(i / heights.width) + ") is " + numberText(heights.pixels[i]) +
                                                " (times the height scale); every height must be finite");
}

Image toHeights(const NpyArray& a, double scale, const std::string& what) {
    if (a.header.shape.size() != 2) throw Error(ErrorCode::Corrupt, what + ": not a 2-D array");
    Image im = makeImage(static_cast<int>(a.header.shape[1]), static_cast<int>(a.header.shape[0]), {"Z"});
    values(a, im.pixels.size(), scale, im.pixels.data());
    checkHeights(im, what);
    return im;
}

bool endsWith(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size()) return false;
    std::string tail = s.substr(s.size() - suffix.size());
    for (char& c : tail) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return tail == suffix;
}

void checkHeightScale(double heightScale) {
    if (!(std::isfinite(heightScale) && heightScale != 0.0))
        throw Error(ErrorCode::InvalidArgument, "height scale " + std::to_string(heightScale) + " must be finite and non-zero");
}

}  // namespace

Dem demFromHeights(Image heights, double heightScale, std::string description) {
    checkHeightScale(heightScale);
    Dem dem;
    dem.heights = std::move(heights);
    if (heightScale != 1.0)
        for (float& h : dem.heights.pixels) h = static_cast<float>(h * heightScale);
    dem.description = std::move(description);
    checkHeights(dem.heights, dem.description);
    return dem;
}

Dem readDem(const std::string& source, double heightScale) {
    checkHeightScale(heightScale);
    Dem dem;
    requireRegularFile(source);
    if (endsWith(source, ".npz")) {
        Npz npz(source);
        // The elevation model: the member named so, else the first 2-D one (by its header alone).
        std::string chosen = npz.has("elevation") ? std::string("elevation") : std::string();
        for (const std::string& name : npz.names())
            if (chosen.empty() && npz.header(name).header.shape.size() == 2) chosen = name;
        if (chosen.empty()) throw Error(ErrorCode::Corrupt, source + ": holds no 2-D array");
        const NpyArray elevation = npz.array(chosen);
        dem.heights = toHeights(elevation, heightScale, source + ":" + chosen);
        const std::string dtype = elevation.header.dtype;
        // matplotlib's sample stores its spacing in degrees of longitude / latitude.
        // A scalar member is read whole only when its header says it holds one value.
        const auto scalarOf = [&](const char* name) {
            if (!npz.has(name) || npz.header(name).header.count != 1) return std::nan("");
            return scalar(npz.array(name));
        };
        const double dx = scalarOf("dx"), dy = scalarOf("dy"), y0 = scalarOf("ymin"), y1 = scalarOf("ymax");
        if (std::isfinite(dx) && std::isfinite(dy) && dx > 0 && dy > 0) {
            if (dx < 0.1 && std::isfinite(y0) && std::isfinite(y1) && std::abs(y0) <= 90) {
                constexpr double kMetresPerDegree = 111320.0;
                const double latitude = 0.5 * (y0 + y1) * 3.14159265358979323846 / 180.0;
                dem.cellMetres = {dx * kMetresPerDegree * std::cos(latitude), dy * kMetresPerDegree};
            } else {
                dem.cellMetres = {dx, dy};
            }
            // A cell from a micrometre to a thousand kilometres; anything else is a damaged file.
            if (!(dem.cellMetres.x >= 1e-6 && dem.cellMetres.x <= 1e6 && dem.cellMetres.y >= 1e-6 && dem.cellMetres.y <= 1e6))
                throw Error(ErrorCode::Corrupt, source + ": spacing dx " + numberText(dx) + ", dy " + numberText(dy) +
                                                    " gives cells of " + numberText(dem.cellMetres.x) + " x " +
                                                    numberText(dem.cellMetres.y) + " m, outside [1e-6, 1e6] m");
        }
        dem.description = source + " " + chosen + " " + std::to_string(dem.heights.width) + "x" +
                          std::to_string(dem.heights.height) + " " + dtype;
        return dem;
    }
    if (endsWith(source, ".npy")) {
        std::ifstream in(source, std::ios::binary);
        if (!in) throw Error(ErrorCode::Io, source + ": cannot open");
        const NpyArray a = readNpy(
            std::filesystem::file_size(source),
            [&](unsigned char* buffer, std::size_t n) {
                if (!in.read(reinterpret_cast<char*>(buffer), static_cast<std::streamsize>(n)))
                    throw Error(ErrorCode::Io, source + ": cannot read (truncated?)");
            },
            source);
        dem.heights = toHeights(a, heightScale, source);
        dem.description = source + " " + std::to_string(dem.heights.width) + "x" + std::to_string(dem.heights.height) +
                          " " + a.header.dtype;
        return dem;
    }
    imageio::ReadOptions raw;  // data: values as they are, never converted
    raw.colorspace = Transfer::Raw;
    const Image image = imageio::readImageFile(source, raw).image;
    if (std::int64_t{image.width} * image.height > kMaxDemSamples)
        throw Error(ErrorCode::LimitExceeded, source + ": " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                                  " holds more than the limit of " + std::to_string(kMaxDemSamples) +
                                                  " height samples");
    int channel = image.channelIndex("Z");
    if (channel < 0) channel = image.channelIndex("Y");
    if (channel < 0) channel = 0;  // a grey or RGB image: its first channel
    dem.heights = makeImage(image.width, image.height, {"Z"});
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            dem.heights.at(x, y) = static_cast<float>(image.at(x, y, channel) * heightScale);
    checkHeights(dem.heights, source);
    dem.description = source + " " + std::to_string(image.width) + "x" + std::to_string(image.height) + " channel " +
                      image.channels[channel];
    return dem;
}

}  // namespace conus::sceneio
