// Private to format/: a bounded walk over a file's raw OpenEXR header bytes, run before any
// OpenEXR code reads the file (exr_io.cpp says why).
#pragma once

#include <cstdint>
#include <string>

#include "conus/core/error.h"
#include "conus/core/limits.h"

namespace conus::format::detail {

struct ScanResult {
    ErrorCode code = ErrorCode::Corrupt;
    std::string problem;  // empty: the headers are well formed and within the limits
};

// Checks every attribute of every part header of the file at `path` (`fileSize` bytes): its size
// non-negative, inside the file and within limits.maxAttributeBytes, each header's bytes within
// limits.maxHeaderBytes, and the value of every attribute whose reader does not follow the
// declared size (chlist, preview, stringvector) exactly as long as declared; chunkCount within
// what the file can hold. Reads the header bytes once and allocates at most one attribute value.
ScanResult scanHeaders(const std::string& path, std::uintmax_t fileSize, const Limits& limits);

}  // namespace conus::format::detail
