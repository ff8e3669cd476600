// Private to format/: the one place that talks to OpenEXR (exr_io.cpp).
#pragma once

#include <string>

#include "conus/core/atomic_file.h"
#include "conus/format/container.h"

namespace conus::format::detail {

struct LoadResult {
    ValidationReport report;
    ErrorCode code = ErrorCode::Corrupt;  // how readConusFile throws when the report is not ok
};

// Opens `path` (a regular file only), checks the headers (OpenEXR's C core, the attribute caps,
// the header rules), then the chunk tables against the file, then (only if all pass) reads the map
// and, when `readPixels`, the image, and checks the map rules. Never throws for bad content: every
// problem lands in the report. `out` is filled only when the report is ok; without `readPixels`
// its image has width, height and channels but no pixels.
LoadResult loadConusFile(const std::string& path, const Limits& limits, bool readPixels, ConusFile& out);

// conus::format::checkExrFile (exr_check.h).
void checkExr(const std::string& path, const Limits& limits);

// Writes an already validated file into `out` (the caller commits it): throws conus::Error(Io)
// naming out.destination() on failure.
void writeExrFile(AtomicFile& out, const ConusFile& file);

}  // namespace conus::format::detail
