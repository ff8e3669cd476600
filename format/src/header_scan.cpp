// The raw header walk of header_scan_pvt.h. OpenEXR's layout ("OpenEXR File Layout"): magic, version
// and flags, then one header (single part) or headers each ended by a null byte and the list ended
// by an empty header (multipart); an attribute is name\0 type\0 int32 size, then size bytes.
#include "header_scan_pvt.h"

#include <cstring>
#include <fstream>
#include <vector>

namespace conus::format::detail {
namespace {

constexpr std::uint32_t kMultipartFlag = 0x1000;
constexpr std::uint32_t kLongNamesFlag = 0x400;

class Reader {
public:
    Reader(const std::string& path, std::uintmax_t size) : m_in(path, std::ios::binary), m_size(size) {}
    bool ok() const { return bool(m_in); }
    std::uintmax_t position() const { return m_position; }
    std::uintmax_t left() const { return m_size - m_position; }

    bool read(void* out, std::size_t n) {
        if (n > left() || !m_in.read(static_cast<char*>(out), static_cast<std::streamsize>(n))) return false;
        m_position += n;
        return true;
    }
    bool skip(std::uintmax_t n) {
        if (n > left() || !m_in.seekg(static_cast<std::streamoff>(n), std::ios::cur)) return false;
        m_position += n;
        return true;
    }
    // A null-terminated name of at most `max` characters; false if longer or cut off.
    bool name(std::string& out, std::size_t max) {
        out.clear();
        for (char c; read(&c, 1);) {
            if (c == '\0') return true;
            if (out.size() == max) return false;
            out += c;
        }
        return false;
    }

private:
    std::ifstream m_in;
    std::uintmax_t m_size;
    std::uintmax_t m_position = 0;
};

std::int32_t int32At(const unsigned char* p) {
    return static_cast<std::int32_t>(std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
                                     std::uint32_t(p[3]) << 24);
}

// "" if the value of an attribute whose C++ reader does not stop at the declared size ends exactly
// there; else what is wrong. (The C core stops at the declared size: where the two disagree, the
// C++ library reads attributes the core never saw.)
std::string checkSelfDelimited(const std::string& type, const std::vector<unsigned char>& v, std::size_t maxName) {
    const std::size_t size = v.size();
    if (type == "chlist") {
        // Entries name\0 + 16 bytes, then the empty name: the last byte.
        std::size_t p = 0;
        while (p < size && v[p] != 0) {
            const void* end = std::memchr(v.data() + p, 0, std::min(size - p, maxName + 1));
            if (!end) return "a channel name runs past the declared size";
            p = static_cast<std::size_t>(static_cast<const unsigned char*>(end) - v.data()) + 1 + 16;
        }
        if (p != size - 1) return "the channel list does not end exactly at its declared size";
    } else if (type == "preview") {
        if (size < 8) return "shorter than its width and height";
        // w * h * 4 == size - 8, without forming w * h (two 32-bit factors overflow 64 bits times 4).
        const std::uint64_t w = std::uint32_t(int32At(v.data())), h = std::uint32_t(int32At(v.data() + 4));
        const std::uint64_t bytes = size - 8, pixels = bytes / 4;
        const bool exact = bytes % 4 == 0 && (w == 0 || h == 0 ? pixels == 0 : pixels % w == 0 && pixels / w == h);
        if (!exact) return "a " + std::to_string(w) + "x" + std::to_string(h) + " preview in " + std::to_string(size) + " bytes";
    } else if (type == "stringvector") {
        std::size_t p = 0;
        while (p < size) {
            if (size - p < 4) return "a string length runs past the declared size";
            const std::int32_t n = int32At(v.data() + p);
            if (n < 0 || std::size_t(n) > size - p - 4) return "a string runs past the declared size";
            p += 4 + std::size_t(n);
        }
    }
    return {};
}

}  // namespace

ScanResult scanHeaders(const std::string& path, std::uintmax_t fileSize, const Limits& limits) {
    Reader in(path, fileSize);
    unsigned char start[8];
    if (!in.ok() || !in.read(start, sizeof start) || int32At(start) != 20000630) return {ErrorCode::Corrupt, "not an OpenEXR file"};
    const std::uint32_t flags = std::uint32_t(int32At(start + 4)) & ~0xffu;
    const bool multipart = flags & kMultipartFlag;
    const std::size_t maxName = flags & kLongNamesFlag ? 255 : 31;
    std::vector<unsigned char> value;
    for (int part = 0;; ++part) {
        const std::string where = "part " + std::to_string(part) + " header";
        std::int64_t headerBytes = 0;
        for (std::string name, type;;) {
            const std::uintmax_t at = in.position();
            if (!in.name(name, maxName)) return {ErrorCode::Corrupt, where + ": attribute name at byte " + std::to_string(at) + " is cut off or too long"};
            if (name.empty()) {
                if (headerBytes > 0) break;
                if (multipart && part > 0) return {};  // the empty header that ends the list
                return {ErrorCode::Corrupt, where + " is empty"};
            }
            unsigned char sizeBytes[4];
            if (!in.name(type, maxName) || !in.read(sizeBytes, 4))
                return {ErrorCode::Corrupt, where + ": attribute `" + name + "` is cut off"};
            const std::int32_t size = int32At(sizeBytes);
            const std::string label = where + ": attribute `" + name + "` (" + type + ")";
            if (size < 0 || std::uintmax_t(size) > in.left()) {
                return {ErrorCode::Corrupt, label + " declares " + std::to_string(size) + " bytes at byte " +
                                                std::to_string(in.position()) + " of a " + std::to_string(fileSize) + "-byte file"};
            }
            if (size > limits.maxAttributeBytes) {
                return {ErrorCode::LimitExceeded, label + " holds " + std::to_string(size) + " bytes, beyond the limit of " +
                                                      std::to_string(limits.maxAttributeBytes) + " bytes an attribute"};
            }
            headerBytes += std::int64_t(name.size() + type.size()) + 6 + size;
            if (headerBytes > limits.maxHeaderBytes) {
                return {ErrorCode::LimitExceeded, where + " holds more than " + std::to_string(limits.maxHeaderBytes) +
                                                      " bytes of attributes, the limit"};
            }
            const bool delimited = type == "chlist" || type == "preview" || type == "stringvector";
            if (delimited || (name == "chunkCount" && type == "int")) {
                value.resize(std::size_t(size));
                if (!in.read(value.data(), value.size())) return {ErrorCode::Corrupt, label + " is cut off"};
                if (delimited) {
                    if (const std::string why = checkSelfDelimited(type, value, maxName); !why.empty())
                        return {ErrorCode::Corrupt, label + ": " + why};
                } else if (size == 4 && (int32At(value.data()) < 0 || std::uintmax_t(int32At(value.data())) * 8 > fileSize)) {
                    return {ErrorCode::Corrupt, label + " = " + std::to_string(int32At(value.data())) +
                                                    " chunks, more offsets than a " + std::to_string(fileSize) + "-byte file holds"};
                }
            } else if (!in.skip(std::uintmax_t(size))) {
                return {ErrorCode::Corrupt, label + " is cut off"};
            }
        }
        if (!multipart) return {};
    }
}

}  // namespace conus::format::detail
