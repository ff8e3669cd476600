// Standard input as a picture (stdin_image_pvt.h): its format by its first bytes, and its bytes
// bounded by what its header declares, so that a stream that never ends is refused early.
#include "stdin_image_pvt.h"

#include <sys/mman.h>

#include <cerrno>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "conus/core/error.h"
#include "conus/core/limits.h"

namespace conus::imageio::oiio {
namespace {

// The most bytes a picture of the stream's kind can take, from the header at its start: a stream
// that runs on past it (a picture's header, then /dev/zero) is refused there, not at the general
// cap. Twice (four times where a coding can grow a picture that far: JPEG, BMP, OpenEXR's
// mipmap and ripmap levels) the samples' bytes, plus kStdinSlack for metadata; sides past
// kMaxImageSide count as that (the reader refuses them). Empty while the header is not all in yet.
// Where the header does not give the size (BigTIFF, deep OpenEXR, a TIFF whose directory comes
// after its pixels) the stream is held to kUnboundedStdinBytes, below what a file may hold.
struct StdinBound {
    std::uintmax_t bytes = 0;
    std::string what;  // "a 640x480 PNG"; empty: the format's header says nothing of the size
};
constexpr std::uintmax_t kMaxStdinBytes = std::uintmax_t{1} << 30;
constexpr std::uintmax_t kUnboundedStdinBytes = std::uintmax_t{256} << 20;
constexpr std::uintmax_t kStdinSlack = std::uintmax_t{64} << 20;
// A Radiance header not ended within this many bytes is no header.
constexpr std::size_t kMaxTextHeader = 64 << 10;

// Reads of the first bytes, each within `bytes` (callers check the length first).
struct Bytes {
    std::span<const unsigned char> b;
    std::uintmax_t be(std::size_t at, int count) const {
        std::uintmax_t v = 0;
        for (int i = 0; i < count; ++i) v = v << 8 | b[at + std::size_t(i)];
        return v;
    }
    std::uintmax_t le(std::size_t at, int count) const {
        std::uintmax_t v = 0;
        for (int i = count - 1; i >= 0; --i) v = v << 8 | b[at + std::size_t(i)];
        return v;
    }
};

std::uintmax_t side(std::uintmax_t s) { return std::min<std::uintmax_t>(s, kMaxImageSide); }

StdinBound bound(std::uintmax_t w, std::uintmax_t h, std::uintmax_t sampleBits, int times, const char* kind) {
    const std::uintmax_t samples = (side(w) * sampleBits + 7) / 8 * side(h);
    return StdinBound{times * samples + kStdinSlack, std::string("a ") + std::to_string(w) + "x" + std::to_string(h) + " " + kind};
}

// The first directory's width, length, bits and samples a pixel. Most writers put the directory
// after the pixels, so the stream up to it is what it is; past it the slack allows for the
// directory's values and further pages.
std::optional<StdinBound> tiffBound(std::span<const unsigned char> b) {
    const std::size_t n = b.size();
    if (n < 8) return std::nullopt;
    const bool big = b[0] == 'M';
    const Bytes r{b};
    const auto read = [&](std::size_t at, int count) { return big ? r.be(at, count) : r.le(at, count); };
    if (read(2, 2) != 42) return StdinBound{kUnboundedStdinBytes, ""};  // BigTIFF: offsets of 8 bytes, not bounded here
    const std::uintmax_t dir = read(4, 4);
    if (dir >= kUnboundedStdinBytes)
        throw Error(ErrorCode::LimitExceeded, "standard input is a TIFF whose first directory is at byte " + std::to_string(dir) + ", past the " +
                                                  std::to_string(kUnboundedStdinBytes >> 20) + " MiB it may hold; give a file instead");
    if (dir + 2 > n) return std::nullopt;
    const std::uintmax_t entries = read(std::size_t(dir), 2);
    if (dir + 2 + 12 * entries + 4 > n) return std::nullopt;
    std::uintmax_t width = 0, length = 0, samplesPerPixel = 1, bits = 1;
    for (std::uintmax_t i = 0; i < entries; ++i) {
        const std::size_t at = std::size_t(dir + 2 + 12 * i);
        const std::uintmax_t tag = read(at, 2), type = read(at + 2, 2), count = read(at + 4, 4);
        const auto value = [&] { return type == 3 ? read(at + 8, 2) : type == 4 ? read(at + 8, 4) : 0; };
        if (tag == 256) width = value();
        if (tag == 257) length = value();
        if (tag == 277) samplesPerPixel = value();
        if (tag == 258 && type == 3) {  // one short a sample: in the entry for up to two, else where it points
            const std::uintmax_t where = count <= 2 ? at + 8 : read(at + 8, 4);
            bits = where + 2 <= n ? read(std::size_t(where), 2) : 64;
        }
    }
    if (width == 0 || length == 0)
        throw Error(ErrorCode::Corrupt, "standard input's TIFF directory at byte " + std::to_string(dir) + " gives no width or length");
    StdinBound tiff = bound(width, length, std::min<std::uintmax_t>(samplesPerPixel, 64) * std::min<std::uintmax_t>(bits, 64), 2, "TIFF");
    tiff.bytes = std::max(tiff.bytes, dir + kStdinSlack);
    return tiff;
}

// Every part's data window and channels, from the attributes of its header (a multi-part file has
// one header a part, the list ended by an empty one). Deep parts hold any number of samples a pixel.
std::optional<StdinBound> exrBound(std::span<const unsigned char> b) {
    const std::size_t n = b.size();
    if (n < 8) return std::nullopt;
    const Bytes r{b};
    const std::uintmax_t flags = r.le(4, 4);
    if (flags & 0x800) return StdinBound{kUnboundedStdinBytes, ""};  // deep data
    const bool multiPart = flags & 0x1000;
    const auto signed32 = [&](std::size_t at) { return std::int64_t(std::int32_t(std::uint32_t(r.le(at, 4)))); };
    // Not all in yet: wait for more, unless the headers already run past what the screen allows.
    const auto more = [&]() -> std::optional<StdinBound> {
        if (n > kStdinSlack)
            throw Error(ErrorCode::LimitExceeded, "standard input's OpenEXR headers run past " + std::to_string(kStdinSlack >> 20) + " MiB");
        return std::nullopt;
    };
    // The text from `at` to its terminating zero, or nothing while it is not all in.
    const auto text = [&](std::size_t& at) -> std::optional<std::string> {
        const auto zero = std::find(b.begin() + std::ptrdiff_t(at), b.end(), 0);
        if (zero == b.end()) return std::nullopt;
        std::string s(b.begin() + std::ptrdiff_t(at), zero);
        at = std::size_t(zero - b.begin()) + 1;
        return s;
    };
    struct Channel {
        std::uintmax_t bytes;
        std::int64_t xSampling, ySampling;
    };
    std::size_t at = 8;
    std::uintmax_t samples = 0, widest = 0, tallest = 0;
    while (true) {
        if (at >= n) return more();
        if (multiPart && b[at] == 0) break;  // the empty header ends the list
        std::int64_t w = 0, h = 0;
        std::vector<Channel> channels;
        while (true) {
            if (at >= n) return more();
            if (b[at] == 0) {
                ++at;
                break;
            }
            const std::optional<std::string> name = text(at), type = name ? text(at) : std::nullopt;
            if (!type || at + 4 > n) return more();
            const std::int64_t size = signed32(at);
            at += 4;
            if (size < 0 || size > kMaxAttributeBytes)
                throw Error(ErrorCode::Corrupt, "standard input's OpenEXR header has an attribute of " + std::to_string(size) +
                                                    " bytes (at most " + std::to_string(kMaxAttributeBytes) + ")");
            if (at + std::size_t(size) > n) return more();
            const std::size_t end = at + std::size_t(size);
            if (*name == "dataWindow" && *type == "box2i" && size == 16) {
                w = std::clamp<std::int64_t>(signed32(at + 8) - signed32(at) + 1, 0, kMaxImageSide);
                h = std::clamp<std::int64_t>(signed32(at + 12) - signed32(at + 4) + 1, 0, kMaxImageSide);
            }
            const auto value = [&] { return std::string(b.begin() + std::ptrdiff_t(at), b.begin() + std::ptrdiff_t(end)); };
            if (*name == "type" && *type == "string" && value().rfind("deep", 0) == 0) return StdinBound{kUnboundedStdinBytes, ""};
            if (*name == "channels" && *type == "chlist") {  // a name, then pixel type, 4 bytes, x and y sampling
                for (std::size_t c = at; c < end && b[c] != 0;) {
                    while (c < end && b[c] != 0) ++c;
                    if (c + 17 > end) break;
                    channels.push_back({r.le(c + 1, 4) == 1 ? 2u : 4u, std::max<std::int64_t>(1, signed32(c + 9)),
                                        std::max<std::int64_t>(1, signed32(c + 13))});
                    c += 17;
                }
            }
            at = end;
        }
        for (const Channel& c : channels)
            samples += c.bytes * std::uintmax_t((w + c.xSampling - 1) / c.xSampling) * std::uintmax_t((h + c.ySampling - 1) / c.ySampling);
        widest = std::max(widest, std::uintmax_t(w));
        tallest = std::max(tallest, std::uintmax_t(h));
        if (!multiPart) break;
    }
    return StdinBound{4 * samples + kStdinSlack, "a " + std::to_string(widest) + "x" + std::to_string(tallest) + " OpenEXR"};
}

// The resolution line after the header's empty line: "-Y 480 +X 640" (either axis first).
std::optional<StdinBound> hdrBound(std::span<const unsigned char> b) {
    const std::string head(b.begin(), b.begin() + std::ptrdiff_t(std::min(b.size(), kMaxTextHeader)));
    const std::size_t blank = head.find("\n\n");
    const std::size_t lineEnd = blank == std::string::npos ? blank : head.find('\n', blank + 2);
    if (lineEnd == std::string::npos && b.size() >= kMaxTextHeader)
        throw Error(ErrorCode::Corrupt, "standard input's Radiance HDR header has no resolution line in its first 64 KiB");
    if (lineEnd == std::string::npos) return std::nullopt;
    char first = 0, second = 0;
    unsigned long a = 0, c = 0;
    if (std::sscanf(head.c_str() + blank + 2, "%*c%c %lu %*c%c %lu", &first, &a, &second, &c) != 4)
        throw Error(ErrorCode::Corrupt, "standard input's Radiance HDR header has no resolution line after its empty line");
    const std::uintmax_t w = first == 'X' ? a : c, h = first == 'X' ? c : a;
    return bound(w, h, 32, 2, "Radiance HDR");  // RGBE, four bytes a pixel; run-length coding grows a row by under 2x
}

// PNM: P1-P6 (width, height and the largest value) and PFM (PF, Pf: width, height, scale).
std::optional<StdinBound> pnmBound(std::span<const unsigned char> b) {
    const std::size_t n = b.size();
    if (n < 2) return std::nullopt;
    const char kind = static_cast<char>(b[1]);
    const bool pfm = kind == 'F' || kind == 'f';
    if (!pfm && (kind < '1' || kind > '6')) return StdinBound{kUnboundedStdinBytes, ""};
    const bool bitmap = kind == '1' || kind == '4', ascii = kind >= '1' && kind <= '3';
    const int wanted = bitmap || pfm ? 2 : 3;
    std::uintmax_t fields[3] = {0, 0, 1};
    int got = 0;
    std::size_t at = 2;
    while (got < wanted && at < n && at < 4096) {
        if (b[at] == '#') {
            while (at < n && b[at] != '\n') ++at;
        } else if (b[at] >= '0' && b[at] <= '9') {
            std::uintmax_t v = 0;
            while (at < n && b[at] >= '0' && b[at] <= '9') v = std::min<std::uintmax_t>(v * 10 + (b[at++] - '0'), 1u << 30);
            if (at == n) return std::nullopt;  // the number may go on
            fields[got++] = v;
        } else {
            ++at;
        }
    }
    if (got < wanted) return at >= 4096 ? std::optional<StdinBound>(StdinBound{kStdinSlack, "a PNM"}) : std::nullopt;
    if (pfm) return bound(fields[0], fields[1], kind == 'F' ? 96 : 32, 2, "PFM");
    const int channels = (kind == '3' || kind == '6') ? 3 : 1;
    // Binary samples take 1 or 2 bytes (a bit for bitmaps); written out, at most a number and a space each.
    const std::uintmax_t bits = ascii ? 8 * 8 : bitmap ? 1 : fields[2] > 255 ? 16 : 8;
    return bound(fields[0], fields[1], bits * channels, 2, "PNM");
}

std::optional<StdinBound> stdinBound(std::span<const unsigned char> b, const std::string& ext) {
    const std::size_t n = b.size();
    const Bytes r{b};
    if (ext == "png") {  // IHDR first: width, height, bit depth, colour type
        if (n < 26) return std::nullopt;
        if (std::memcmp(&b[12], "IHDR", 4) != 0) return StdinBound{kStdinSlack, "a PNG without its header"};
        const int channels = b[25] == 2 ? 3 : b[25] == 4 ? 2 : b[25] == 6 ? 4 : 1;
        return bound(r.be(16, 4), r.be(20, 4), std::uintmax_t(channels) * b[24] + 8, 2, "PNG");  // + a filter byte a row
    }
    if (ext == "bmp") {  // BITMAPINFOHEADER: width, height (negative: top-down), bits a pixel
        if (n < 30) return std::nullopt;
        const std::uintmax_t h = r.le(22, 4);
        return bound(r.le(18, 4) & 0x7fffffffu, (h & 0x80000000u) ? (~h + 1) & 0xffffffffu : h, std::max<std::uintmax_t>(r.le(28, 2), 32), 4, "BMP");
    }
    if (ext == "jpg") {  // the segments up to the frame header (SOFn: height, width, components)
        std::size_t at = 2;
        while (at + 4 <= n) {
            if (b[at] != 0xFF) return StdinBound{kUnboundedStdinBytes, ""};
            const unsigned marker = b[at + 1];
            if (marker == 0xFF) {
                ++at;
                continue;
            }
            const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
            if (frame) {
                if (at + 10 > n) return std::nullopt;
                return bound(r.be(at + 7, 2), r.be(at + 5, 2), 8 * std::uintmax_t(b[at + 9]), 4, "JPEG");
            }
            at += 2 + r.be(at + 2, 2);
        }
        return n > (std::size_t{16} << 20) ? std::optional<StdinBound>(StdinBound{kUnboundedStdinBytes, ""}) : std::nullopt;
    }
    if (ext == "ppm") return pnmBound(b);
    if (ext == "tif") return tiffBound(b);
    if (ext == "exr") return exrBound(b);
    if (ext == "hdr") return hdrBound(b);
    return StdinBound{kUnboundedStdinBytes, ""};
}

}  // namespace

const char* stdinExtension(std::span<const unsigned char> bytes) {
    const auto starts = [&](const char* magic, std::size_t size) {
        return bytes.size() >= size && std::memcmp(bytes.data(), magic, size) == 0;
    };
    return starts("\x89PNG", 4)                          ? "png"
           : starts("\xFF\xD8\xFF", 3)                   ? "jpg"
           : starts("II*\0", 4) || starts("MM\0*", 4) || starts("II+\0", 4) || starts("MM\0+", 4) ? "tif"
           : starts("\x76\x2f\x31\x01", 4)               ? "exr"
           : starts("BM", 2)                               ? "bmp"
           : starts("#?", 2)                               ? "hdr"
           : bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] != 0 && std::strchr("123456Ff", bytes[1]) ? "ppm"
                                                           : "";
}

StdinBytes::StdinBytes(std::size_t capacity) : m_capacity(capacity) {
    void* base = ::mmap(nullptr, capacity, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (base == MAP_FAILED)
        throw Error(ErrorCode::Io, "cannot hold standard input: " + std::string(std::strerror(errno)) + "; give a file instead");
    m_base = static_cast<unsigned char*>(base);
}

StdinBytes::StdinBytes(StdinBytes&& other) noexcept
    : m_base(std::exchange(other.m_base, nullptr)),
      m_capacity(std::exchange(other.m_capacity, 0)),
      m_size(std::exchange(other.m_size, 0)) {}

StdinBytes& StdinBytes::operator=(StdinBytes&& other) noexcept {
    if (this != &other) {
        StdinBytes old(std::move(*this));
        m_base = std::exchange(other.m_base, nullptr);
        m_capacity = std::exchange(other.m_capacity, 0);
        m_size = std::exchange(other.m_size, 0);
    }
    return *this;
}

StdinBytes::~StdinBytes() {
    if (m_base) ::munmap(m_base, m_capacity);
}

void StdinBytes::append(const unsigned char* bytes, std::size_t count) {
    if (count > m_capacity - m_size) throw Error(ErrorCode::LimitExceeded, "standard input runs past the bytes kept for it");
    std::memcpy(m_base + m_size, bytes, count);
    m_size += count;
}

StdinImage readStdin() {
    const char* notAnImage = "standard input is not an image format CoNUS recognizes (PNG, JPEG, TIFF, EXR, BMP, HDR, PPM)";
    StdinImage in{StdinBytes(kMaxStdinBytes), ""};
    unsigned char chunk[1 << 16];
    std::size_t n;
    std::string ext;
    std::optional<StdinBound> limit;
    while ((n = std::fread(chunk, 1, sizeof chunk, stdin)) > 0) {
        // Refused before the bytes past the cap are kept.
        const std::uintmax_t cap = limit ? std::min(limit->bytes, kMaxStdinBytes) : kUnboundedStdinBytes;
        if (in.bytes.size() + n > cap) {
            if (limit && !limit->what.empty() && limit->bytes < kMaxStdinBytes)
                throw Error(ErrorCode::LimitExceeded, "standard input runs past " + std::to_string(cap) + " bytes, more than " +
                                                          limit->what + " can take (its header says what follows)");
            throw Error(ErrorCode::LimitExceeded, "standard input holds more than " + std::to_string(cap >> 20) +
                                                      " MiB; give a file instead");
        }
        in.bytes.append(chunk, n);
        // The format by its first bytes before reading on: an endless stream that is no picture
        // (/dev/zero, a log) is refused at once; one that is, past what its header declares.
        if (ext.empty() && in.bytes.size() >= 4) {
            ext = stdinExtension(in.bytes.view());
            if (ext.empty()) throw Error(ErrorCode::Io, notAnImage);
        }
        if (!ext.empty() && !limit) limit = stdinBound(in.bytes.view(), ext);
    }
    if (in.bytes.size() == 0) throw Error(ErrorCode::Io, "standard input is empty");
    const char* name = stdinExtension(in.bytes.view());
    if (!*name) throw Error(ErrorCode::Io, notAnImage);
    in.name = std::string("stdin.") + name;
    return in;
}

}  // namespace conus::imageio::oiio
