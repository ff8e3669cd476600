// Volume files read into conus::Volume (core/volume.h): dense float samples, x fastest. One file
// per library at the edge: OpenVDB in sceneio/src/openvdb_volume.cpp, teem's NRRD in
// nrrd_volume.cpp; raw bricks and VolPack's .den in raw_volume.cpp (plain byte layouts, no library).
//
// Shared rules: every size that comes from a file or a command line is checked in 64-bit
// arithmetic against the caps below and against the file's own length before anything is
// allocated; a volume with a NaN or infinite sample is refused (core's checkVolume). Errors are one-line
// conus::Error naming the path: Io (missing or unreadable), Corrupt (a header that lies about the
// payload, a truncated file, a non-finite sample), LimitExceeded (past a cap), InvalidArgument (a
// malformed raw specification), Unsupported (a sample type or grid type not read).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "conus/core/enum_names.h"
#include "conus/core/limits.h"
#include "conus/core/volume.h"

namespace conus::sceneio {

// The default caps (core/limits.h); a caller may lower them.
using conus::kMaxVolumeSide;
using conus::kMaxVolumeVoxels;

struct VolumeReadOptions {
    std::int64_t maxVoxels = kMaxVolumeVoxels;
    std::string gridName;  // OpenVDB: the float grid to read ("" = the first float grid)
    std::vector<std::string> allowedDirs;  // NRRD: folders besides the header's own its data files may lie in (named_files.h)
};

enum class RawType { UInt8, UInt16, Float32 };

constexpr auto enumNameTable(RawType) {
    return makeEnumNameTable<RawType>(
        "raw sample type", {{RawType::UInt8, "uint8"}, {RawType::UInt16, "uint16"}, {RawType::Float32, "float32"}});
}

// A raw brick's layout: what the command line says, since the file says nothing.
struct RawLayout {
    int width = 0, height = 0, depth = 0;
    RawType type = RawType::UInt8;
    glm::dvec3 spacing{1.0, 1.0, 1.0};
    bool bigEndian = false;  // byte order of uint16 and float32 samples
};

// core's checkVolume for a volume read from a file: its refusals (a side below 2, a spacing that
// is not positive, a NaN sample) are bad data, Corrupt, not InvalidArgument; and the extent
// (sides times spacing) must be finite.
void checkFileVolume(const Volume& volume, const std::string& what);

// Throws conus::Error(InvalidArgument) for a side below 2; LimitExceeded for a side past
// kMaxVolumeSide or more than maxVoxels samples.
void checkDimensions(const std::string& what, std::int64_t width, std::int64_t height, std::int64_t depth,
                     std::int64_t maxVoxels = kMaxVolumeVoxels);

// A raw file holding exactly width * height * depth samples of the layout's type (no header).
Volume readRawVolume(const std::string& path, const RawLayout& layout, const VolumeReadOptions& options = {});
// VolPack's density file (.den): a 62-byte header (either byte order) and 8-bit samples.
Volume readDenVolume(const std::string& path, const VolumeReadOptions& options = {});
// NRRD (.nrrd, .nhdr with its data files, which follow named_files.h) through teem: 3-D, any scalar type (converted to float),
// spacing from the header's spacings or space directions when present.
Volume readNrrdVolume(const std::string& path, const VolumeReadOptions& options = {});
// OpenVDB (.vdb): a float grid, sparse or dense, densified over its active bounding box (the
// background value outside active voxels); spacing from the grid's voxel size.
Volume readVdbVolume(const std::string& path, const VolumeReadOptions& options = {});

// Writes `volume` as an OpenVDB float grid "density" (voxels equal to `background` left inactive),
// through a temporary renamed over `path`: for conversions and tests.
void writeVdbVolume(const std::string& path, const Volume& volume, float background = 0.0f);

// "raw:WxHxD:uint8|uint16|float32[:spacing]:path": the raw form with RawType's names, for messages and help.
std::string rawVolumeForm();

// rawVolumeForm() (spacing "s" or "sx,sy,sz") -> path and layout. Throws
// conus::Error(InvalidArgument) naming what is malformed.
struct RawSpec {
    std::string path;
    RawLayout layout;
};
RawSpec parseRawSpec(const std::string& spec);

// By the specification's form: "raw:..." (parseRawSpec), else by extension: .den, .nrrd/.nhdr,
// .vdb. Anything else throws conus::Error(Unsupported) listing the forms read.
Volume readVolume(const std::string& spec, const VolumeReadOptions& options = {});

}  // namespace conus::sceneio
