// A reflection asset in one file (spec/conus-format.md, "Reflection assets"): the six faces of a
// cube around a reflector's centre, each an ordinary CoNUS depth image stored as its own pair of
// parts (`conus.px` + `samplingmap.px`, ...), with the cube's frame in the first face's header.
//
// The rules of container.h hold here too: the writer validates first and writes through
// conus::AtomicFile (nothing under the final name unless the whole asset was written); the reader
// checks every face as readConusFile checks a file, then the asset's rules (V18, V19), before it
// commits memory for pixels, and throws conus::Error with one line.
#pragma once

#include <array>
#include <string>

#include "conus/format/container.h"

namespace conus::format {

inline constexpr int kCubeFaceCount = 6;
// The faces in file order: the cube's +x, -x, +y, -y, +z, -z. Face `f` is stored in the parts
// `conus.<f>` (its image) and `samplingmap.<f>` (its map).
inline constexpr const char* kCubeFaceNames[kCubeFaceCount] = {"px", "nx", "py", "ny", "pz", "nz"};

// Where each face looks and which way is up in its image, in the cube frame's axes (the usual
// cube-map layout): forward x, y, z, then up x, y, z.
inline constexpr std::array<std::array<int, 6>, kCubeFaceCount> kCubeFaceAxes{{
    {1, 0, 0, 0, 1, 0},
    {-1, 0, 0, 0, 1, 0},
    {0, 1, 0, 0, 0, -1},
    {0, -1, 0, 0, 0, 1},
    {0, 0, 1, 0, 1, 0},
    {0, 0, -1, 0, 1, 0},
}};

// The cube's frame: its centre (every face's eye) and its axes in world space.
struct CubeFrame {
    std::array<float, 3> centre{};
    std::array<float, 9> axes{1, 0, 0, 0, 1, 0, 0, 0, 1};  // row-major: rows the cube's +x, +y, +z
};

struct ReflectionAssetFile {
    CubeFrame frame;
    // In kCubeFaceNames' order; each a depth image (dataKind depthimage, channels R, G, B, A, Z)
    // whose camera is its face's: eye at the centre, 90 degrees, square.
    std::array<ConusFile, kCubeFaceCount> faces;
};

void writeReflectionAsset(const std::string& path, const ReflectionAssetFile& asset);
ReflectionAssetFile readReflectionAsset(const std::string& path, const Limits& limits = {});
// Everything but the faces' pixels (what `conus info` needs), checked as readConusHeader checks.
ReflectionAssetFile readReflectionAssetHeader(const std::string& path, const Limits& limits = {});

// Every violated rule of an in-memory asset: each face's as validateConusFile's, then V18 and V19.
// (validateConusFile(path) validates a reflection asset's file the same way.)
ValidationReport validateReflectionAsset(const ReflectionAssetFile& asset);

// Whether the file at `path` is laid out as a reflection asset (no `conus` part, a `conus.px`
// part); false for anything unreadable, which the readers then report.
bool isReflectionAsset(const std::string& path);

}  // namespace conus::format
