// Private to format/: the one place that talks to OpenEXR (exr_io.cpp).
#pragma once

#include <string>

#include "conus/core/atomic_file.h"
#include "conus/format/container.h"
#include "conus/format/reflection_asset.h"

namespace conus::format::detail {

struct LoadResult {
    ValidationReport report;
    ErrorCode code = ErrorCode::Corrupt;  // how readConusFile throws when the report is not ok
};

// Opens `path` (a regular file only), checks the headers (OpenEXR's C core, the attribute caps,
// the header rules), then the chunk tables against the file, then (only if all pass) reads the map
// and, when `readPixels`, the image, and checks the map rules. Never throws for bad content: every
// problem lands in the report. `out` is filled only when the report is ok; without `readPixels`
// its image has width, height and channels but no pixels. A reflection asset is refused, naming
// what reads it.
LoadResult loadConusFile(const std::string& path, const Limits& limits, bool readPixels, ConusFile& out);
// The same for a reflection asset: every face as above, then the asset's rules (V18, V19). A
// single CoNUS image is refused, saying how to make an asset.
LoadResult loadReflectionAsset(const std::string& path, const Limits& limits, bool readPixels, ReflectionAssetFile& out);
// Whichever of the two the file is, checked as its loader checks it.
LoadResult validateFile(const std::string& path, const Limits& limits, bool readPixels);
// Whether the file's parts are a reflection asset's; false for an unreadable file.
bool hasReflectionLayout(const std::string& path);

// conus::format::checkExrFile (exr_check.h).
void checkExr(const std::string& path, const Limits& limits);

// Writes an already validated file (or asset) into `out` (the caller commits it): throws
// conus::Error(Io) naming out.destination() on failure.
void writeExrFile(AtomicFile& out, const ConusFile& file);
void writeExrFile(AtomicFile& out, const ReflectionAssetFile& asset);

}  // namespace conus::format::detail
