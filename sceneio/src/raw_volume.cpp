// Raw bricks and VolPack's .den: byte layouts read with the standard library (no library reads
// them better). Every length is checked against the file's size before the samples are allocated.
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "conus/core/error.h"
#include "conus/sceneio/volume_file.h"

namespace conus::sceneio {
namespace {

namespace fs = std::filesystem;

std::uintmax_t fileBytes(const std::string& what, const std::string& path) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throw Error(ErrorCode::Io, what + ": no such file");
    if (!fs::is_regular_file(status)) throw Error(ErrorCode::Io, what + ": not a regular file");
    const std::uintmax_t bytes = fs::file_size(path, ec);
    if (ec) throw Error(ErrorCode::Io, what + ": cannot read its size (" + ec.message() + ")");
    return bytes;
}

std::vector<unsigned char> readBytes(const std::string& what, const std::string& path, std::uintmax_t offset,
                                     std::uintmax_t count) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::Io, what + ": cannot open it");
    std::vector<unsigned char> bytes(count);
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(count));
    if (in.gcount() != static_cast<std::streamsize>(count))
        throw Error(ErrorCode::Corrupt, what + ": truncated (read " + std::to_string(in.gcount()) + " of " +
                                            std::to_string(count) + " bytes)");
    return bytes;
}

bool hostIsLittleEndian() {
    const std::uint16_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    return first == 1;
}

// Samples of `size` bytes each in the file's byte order -> the host's.
void toHostOrder(std::vector<unsigned char>& bytes, std::size_t size, bool bigEndian) {
    if (size == 1 || bigEndian == !hostIsLittleEndian()) return;
    for (std::size_t i = 0; i + size <= bytes.size(); i += size)
        for (std::size_t k = 0; k < size / 2; ++k) std::swap(bytes[i + k], bytes[i + size - 1 - k]);
}

std::size_t sampleBytes(RawType type) { return type == RawType::UInt8 ? 1 : type == RawType::UInt16 ? 2 : 4; }

// The file's bytes and the float samples, held together while converting.
void checkReadBytes(const std::string& what, std::uint64_t voxels, std::size_t size) {
    const std::uint64_t bytes = voxels * (size + sizeof(float));
    if (bytes > std::uint64_t(kMaxVolumeReadBytes))
        throw Error(ErrorCode::LimitExceeded, what + ": reading " + std::to_string(voxels) + " samples takes " +
                                                  std::to_string(bytes) + " bytes, more than the limit of " +
                                                  std::to_string(kMaxVolumeReadBytes));
}

}  // namespace

Volume readRawVolume(const std::string& path, const RawLayout& layout, const VolumeReadOptions& options) {
    const std::string what = "raw volume '" + path + "'";
    checkDimensions(what, layout.width, layout.height, layout.depth, options.maxVoxels);
    checkReadBytes(what, std::uint64_t(layout.width) * layout.height * layout.depth, sampleBytes(layout.type));
    const std::uintmax_t voxels = std::uintmax_t(layout.width) * layout.height * layout.depth;
    const std::size_t size = sampleBytes(layout.type);
    const std::uintmax_t expected = voxels * size;
    const std::uintmax_t actual = fileBytes(what, path);
    if (actual != expected)
        throw Error(ErrorCode::Corrupt, what + ": holds " + std::to_string(actual) + " bytes, but " +
                                            std::to_string(layout.width) + "x" + std::to_string(layout.height) + "x" +
                                            std::to_string(layout.depth) + " samples of " + std::to_string(size) +
                                            " bytes need " + std::to_string(expected));
    std::vector<unsigned char> bytes = readBytes(what, path, 0, expected);
    toHostOrder(bytes, size, layout.bigEndian);
    Volume volume;
    volume.width = layout.width;
    volume.height = layout.height;
    volume.depth = layout.depth;
    volume.spacing = layout.spacing;
    volume.values.resize(voxels);
    for (std::size_t i = 0; i < voxels; ++i) {
        if (layout.type == RawType::UInt8) {
            volume.values[i] = bytes[i];
        } else if (layout.type == RawType::UInt16) {
            std::uint16_t v;
            std::memcpy(&v, &bytes[i * 2], 2);
            volume.values[i] = v;
        } else {
            std::memcpy(&volume.values[i], &bytes[i * 4], 4);
        }
    }
    checkFileVolume(volume, what);
    return volume;
}

// VolPack's header (vp_file.c's density file): short version 1; 27 shorts (original, extracted and
// mapped min, max and length per axis); short warps; int32 payload length; then the bytes.
Volume readDenVolume(const std::string& path, const VolumeReadOptions& options) {
    const std::string what = "den volume '" + path + "'";
    constexpr std::size_t kHeaderBytes = 62;
    const std::uintmax_t bytes = fileBytes(what, path);
    if (bytes < kHeaderBytes)
        throw Error(ErrorCode::Corrupt, what + ": " + std::to_string(bytes) + " bytes, shorter than the 62-byte header");
    std::vector<unsigned char> header = readBytes(what, path, 0, kHeaderBytes);
    // Version 1 tells the byte order: 01 00 is little-endian, 00 01 big-endian.
    bool big;
    if (header[0] == 1 && header[1] == 0) big = false;
    else if (header[0] == 0 && header[1] == 1) big = true;
    else throw Error(ErrorCode::Corrupt, what + ": not a VolPack density file (version field is not 1)");
    const auto u16 = [&](std::size_t at) {
        return big ? (unsigned(header[at]) << 8 | header[at + 1]) : (unsigned(header[at + 1]) << 8 | header[at]);
    };
    const int width = int(u16(2 + 24 * 2)), height = int(u16(2 + 25 * 2)), depth = int(u16(2 + 26 * 2));
    const std::uint32_t length =
        big ? (std::uint32_t(header[58]) << 24 | std::uint32_t(header[59]) << 16 | std::uint32_t(header[60]) << 8 | header[61])
            : (std::uint32_t(header[61]) << 24 | std::uint32_t(header[60]) << 16 | std::uint32_t(header[59]) << 8 | header[58]);
    checkDimensions(what, width, height, depth, options.maxVoxels);
    const std::uintmax_t voxels = std::uintmax_t(width) * height * depth;
    checkReadBytes(what, voxels, 1);
    if (length != voxels)
        throw Error(ErrorCode::Corrupt, what + ": the header's length " + std::to_string(length) + " is not " +
                                            std::to_string(width) + "x" + std::to_string(height) + "x" +
                                            std::to_string(depth) + " = " + std::to_string(voxels));
    if (bytes != kHeaderBytes + voxels)
        throw Error(ErrorCode::Corrupt, what + ": holds " + std::to_string(bytes - kHeaderBytes) +
                                            " bytes of samples, but its header declares " + std::to_string(voxels));
    const std::vector<unsigned char> samples = readBytes(what, path, kHeaderBytes, voxels);
    Volume volume;
    volume.width = width;
    volume.height = height;
    volume.depth = depth;
    volume.values.assign(samples.begin(), samples.end());
    return volume;
}

}  // namespace conus::sceneio
