// Screening of any OpenEXR file before an OpenEXR reader sees it (OpenImageIO's included): the
// checks readConusFile runs on its own files, for the EXRs that come in as pictures.
#pragma once

#include <string>

#include "conus/core/limits.h"

namespace conus::format {

// Returns when the OpenEXR file at `path` (a regular file) is safe to read: every header
// attribute inside the file and within `limits` (checked on the raw bytes, before anything is
// allocated), the headers as OpenEXR's C core parses them, and every part's chunk table inside the
// file, with no chunk declaring more pixels than its bytes can expand to. A reader that passes
// this allocates no more than the file can really hold. Otherwise throws conus::Error (Corrupt,
// LimitExceeded or Io) with one line that names the file.
void checkExrFile(const std::string& path, const Limits& limits = {});

}  // namespace conus::format
