// Standard input as a picture (stdin_image_pvt.h): its format by its first bytes, and its bytes
// bounded by what its header declares, so that a stream that never ends is refused early.
#include "stdin_image_pvt.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "conus/core/error.h"
#include "conus/core/limits.h"

namespace conus::imageio::oiio {
namespace {

// The most bytes a picture of the stream's kind can take, from the header at its start: a stream
// that runs on past it (a picture's header, then /dev/zero) is refused there, not at the general
// cap. Twice (four times for JPEG and BMP, whose codings can grow a picture that far) the samples'
// bytes, plus kStdinSlack for metadata; sides past kMaxImageSide count as that (the reader refuses
// them). Empty while the header is not all in yet; formats whose first bytes do not
// give the size (TIFF keeps its directory anywhere; OpenEXR, Radiance HDR, PAM) get the general cap.
struct StdinBound {
    std::uintmax_t bytes = 0;
    std::string what;  // "a 640x480 PNG"
};
constexpr std::uintmax_t kMaxStdinBytes = std::uintmax_t{1} << 30;
constexpr std::uintmax_t kStdinSlack = std::uintmax_t{64} << 20;

std::optional<StdinBound> stdinBound(const std::vector<unsigned char>& b, const std::string& ext) {
    const std::size_t n = b.size();
    const auto be = [&](std::size_t at, int bytes) {
        std::uintmax_t v = 0;
        for (int i = 0; i < bytes; ++i) v = v << 8 | b[at + std::size_t(i)];
        return v;
    };
    const auto le = [&](std::size_t at, int bytes) {
        std::uintmax_t v = 0;
        for (int i = bytes - 1; i >= 0; --i) v = v << 8 | b[at + std::size_t(i)];
        return v;
    };
    const auto side = [](std::uintmax_t s) { return std::min<std::uintmax_t>(s, kMaxImageSide); };
    const auto bound = [&](std::uintmax_t w, std::uintmax_t h, std::uintmax_t sampleBits, int times, const char* kind) {
        const std::uintmax_t samples = (side(w) * sampleBits + 7) / 8 * side(h);
        return StdinBound{times * samples + kStdinSlack,
                          std::string("a ") + std::to_string(w) + "x" + std::to_string(h) + " " + kind};
    };
    if (ext == "png") {  // IHDR first: width, height, bit depth, colour type
        if (n < 26) return std::nullopt;
        if (std::memcmp(&b[12], "IHDR", 4) != 0) return StdinBound{kStdinSlack, "a PNG without its header"};
        const int channels = b[25] == 2 ? 3 : b[25] == 4 ? 2 : b[25] == 6 ? 4 : 1;
        return bound(be(16, 4), be(20, 4), std::uintmax_t(channels) * b[24] + 8, 2, "PNG");  // + a filter byte a row
    }
    if (ext == "bmp") {  // BITMAPINFOHEADER: width, height (negative: top-down), bits a pixel
        if (n < 30) return std::nullopt;
        const std::uintmax_t h = le(22, 4);
        return bound(le(18, 4) & 0x7fffffffu, (h & 0x80000000u) ? (~h + 1) & 0xffffffffu : h, std::max<std::uintmax_t>(le(28, 2), 32), 4, "BMP");
    }
    if (ext == "jpg") {  // the segments up to the frame header (SOFn: height, width, components)
        std::size_t at = 2;
        while (at + 4 <= n) {
            if (b[at] != 0xFF) return StdinBound{kMaxStdinBytes, "a JPEG"};
            const unsigned marker = b[at + 1];
            if (marker == 0xFF) {
                ++at;
                continue;
            }
            const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
            if (frame) {
                if (at + 10 > n) return std::nullopt;
                return bound(be(at + 7, 2), be(at + 5, 2), 8 * std::uintmax_t(b[at + 9]), 4, "JPEG");
            }
            at += 2 + be(at + 2, 2);
        }
        return n > (std::size_t{16} << 20) ? std::optional<StdinBound>(StdinBound{kMaxStdinBytes, "a JPEG"}) : std::nullopt;
    }
    if (ext == "ppm" && n >= 2 && b[1] >= '1' && b[1] <= '6') {  // P1-P6: width, height (and the largest value)
        const bool bitmap = b[1] == '1' || b[1] == '4', ascii = b[1] <= '3';
        std::uintmax_t fields[3] = {0, 0, 1};
        int got = 0;
        std::size_t at = 2;
        while (got < (bitmap ? 2 : 3) && at < n && at < 4096) {
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
        if (got < (bitmap ? 2 : 3)) return at >= 4096 ? std::optional<StdinBound>(StdinBound{kStdinSlack, "a PNM"}) : std::nullopt;
        const int channels = (b[1] == '3' || b[1] == '6') ? 3 : 1;
        // Binary samples take 1 or 2 bytes (a bit for bitmaps); written out, at most a number and a space each.
        const std::uintmax_t bits = ascii ? 8 * 8 : bitmap ? 1 : fields[2] > 255 ? 16 : 8;
        return bound(fields[0], fields[1], bits * channels, 2, "PNM");
    }
    return StdinBound{kMaxStdinBytes, ""};
}

}  // namespace

const char* stdinExtension(const std::vector<unsigned char>& bytes) {
    const auto starts = [&](const char* magic, std::size_t size) {
        return bytes.size() >= size && std::memcmp(bytes.data(), magic, size) == 0;
    };
    return starts("\x89PNG", 4)                          ? "png"
           : starts("\xFF\xD8\xFF", 3)                   ? "jpg"
           : starts("II*\0", 4) || starts("MM\0*", 4)     ? "tif"
           : starts("\x76\x2f\x31\x01", 4)               ? "exr"
           : starts("BM", 2)                               ? "bmp"
           : starts("#?", 2)                               ? "hdr"
           : bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] != 0 && std::strchr("1234567Ff", bytes[1]) ? "ppm"
                                                           : "";
}

StdinImage readStdin() {
    const char* notAnImage = "standard input is not an image format CoNUS recognizes (PNG, JPEG, TIFF, EXR, BMP, HDR, PPM)";
    StdinImage in;
    unsigned char chunk[1 << 16];
    std::size_t n;
    std::string ext;
    std::optional<StdinBound> limit;
    while ((n = std::fread(chunk, 1, sizeof chunk, stdin)) > 0) {
        // Refused before the bytes past the cap are kept (the buffer never grows past it).
        const std::uintmax_t cap = limit ? std::min(limit->bytes, kMaxStdinBytes) : kMaxStdinBytes;
        if (in.bytes.size() + n > cap) {
            if (limit && !limit->what.empty() && limit->bytes < kMaxStdinBytes)
                throw Error(ErrorCode::LimitExceeded, "standard input runs past " + std::to_string(cap) + " bytes, more than " +
                                                          limit->what + " can take (its header says what follows)");
            throw Error(ErrorCode::LimitExceeded, "standard input holds more than " + std::to_string(cap >> 20) +
                                                      " MiB; give a file instead");
        }
        in.bytes.insert(in.bytes.end(), chunk, chunk + n);
        // The format by its first bytes before reading on: an endless stream that is no picture
        // (/dev/zero, a log) is refused at once; one that is, past what its header declares.
        if (ext.empty() && in.bytes.size() >= 4) {
            ext = stdinExtension(in.bytes);
            if (ext.empty()) throw Error(ErrorCode::Io, notAnImage);
        }
        if (!ext.empty() && !limit) {
            limit = stdinBound(in.bytes, ext);
            // Room for all it may hold at once (untouched pages cost nothing): no copy as it grows.
            if (limit) in.bytes.reserve(std::min(limit->bytes, kMaxStdinBytes));
        }
    }
    if (in.bytes.empty()) throw Error(ErrorCode::Io, "standard input is empty");
    const char* name = stdinExtension(in.bytes);
    if (!*name) throw Error(ErrorCode::Io, notAnImage);
    in.name = std::string("stdin.") + name;
    return in;
}

}  // namespace conus::imageio::oiio
