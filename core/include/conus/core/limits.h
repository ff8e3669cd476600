// The resource limits of CoNUS, stated once. Every reader checks a size that comes from a file (or
// a command line) against these, in 64-bit arithmetic, before it allocates; `conus info --limits`
// prints them and spec/conus-format.md ("Limits") lists the same values. A caller may tighten them
// through a Limits value (format::ReadLimits is this struct); the constants are the defaults.
// Standard types only, so that every library, the CLI and the Python module can include it.
#pragma once

#include <array>
#include <cstdint>

namespace conus {

// Images: every image any CoNUS library allocates (sources, CoNUS images, decoded frames).
inline constexpr int kMaxImageSide = 1 << 16;                            // pixels a side
inline constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 30;  // width * height
inline constexpr int kMaxChannels = 64;                                  // channels of a CoNUS image
inline constexpr std::int64_t kMaxTilePixels = std::int64_t{1} << 24;   // pixels of one tile of a tiled part

// Sampling maps: nodes per side (spec V7) and in all.
inline constexpr int kMinMapSide = 2;
inline constexpr int kMaxMapSide = 4097;
inline constexpr std::int64_t kMaxMapNodes = std::int64_t{kMaxMapSide} * kMaxMapSide;

// File headers: bytes of one attribute's value, and of all attribute values of one part.
inline constexpr std::int64_t kMaxAttributeBytes = std::int64_t{1} << 20;
inline constexpr std::int64_t kMaxHeaderBytes = std::int64_t{4} << 20;

// The inverse map's index (SamplingMap::undistort): at most kIndexBytesPerCell per map cell plus
// kIndexBytesBase, and never more than kMaxIndexBytes, whatever the map's shape.
inline constexpr std::int64_t kIndexBytesPerCell = 128;
inline constexpr std::int64_t kIndexBytesBase = std::int64_t{64} << 10;
inline constexpr std::int64_t kMaxIndexBytes = std::int64_t{512} << 20;

// Memory for one decode: the CoNUS image's pixels as float plus the output frame's.
inline constexpr std::int64_t kMaxDecodeBytes = std::int64_t{8} << 30;

// The caps a reader applies; a caller may lower any of them (never raise them past the constants:
// the constants are also what the format's own rules allow).
struct Limits {
    std::int64_t maxPixels = kMaxImagePixels;             // CoNUS image pixels
    int maxMapSide = kMaxMapSide;                         // sampling-map nodes per side
    int maxChannels = kMaxChannels;                       // CoNUS image channels
    std::int64_t maxAttributeBytes = kMaxAttributeBytes;  // one attribute value
    std::int64_t maxHeaderBytes = kMaxHeaderBytes;        // all attribute values of one part
    std::int64_t maxDecodeBytes = kMaxDecodeBytes;        // CoNUS image as float + output frame
};

// One limit as `conus info --limits` prints it and the spec lists it.
struct LimitEntry {
    const char* name;     // JSON key
    std::int64_t value;
    const char* unit;     // "pixels", "bytes", ...
    const char* meaning;  // one line
};

inline constexpr std::array<LimitEntry, 13> limitTable() {
    return {{
        {"imageSide", kMaxImageSide, "pixels", "width or height of any image (CoNUS image, source, decoded frame)"},
        {"imagePixels", kMaxImagePixels, "pixels", "width x height of any image"},
        {"channels", kMaxChannels, "channels", "channels of a CoNUS image"},
        {"tilePixels", kMaxTilePixels, "pixels", "pixels of one tile of a tiled `conus` part"},
        {"mapSideMin", kMinMapSide, "nodes", "sampling-map nodes per side, at least"},
        {"mapSide", kMaxMapSide, "nodes", "sampling-map nodes per side, at most"},
        {"mapNodes", kMaxMapNodes, "nodes", "sampling-map nodes in all"},
        {"attributeBytes", kMaxAttributeBytes, "bytes", "value of one header attribute"},
        {"headerBytes", kMaxHeaderBytes, "bytes", "attribute values of one part's header"},
        {"indexBytesPerCell", kIndexBytesPerCell, "bytes", "inverse-map index per map cell (plus indexBytesBase)"},
        {"indexBytesBase", kIndexBytesBase, "bytes", "inverse-map index, fixed allowance"},
        {"indexBytes", kMaxIndexBytes, "bytes", "inverse-map index in all"},
        {"decodeBytes", kMaxDecodeBytes, "bytes", "one decode: CoNUS image as float plus the output frame"},
    }};
}

}  // namespace conus
