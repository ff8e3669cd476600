// One file open in conus-view: the CoNUS file and its map, or the reason it could not be opened.
// Loading never throws: a file that is not a valid CoNUS file becomes a Document with an error,
// which the window shows (title, stderr) instead of crashing.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "conus/codec/builders/foci.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"
#include "conus/format/container.h"

namespace conus::viewer {

struct Document {
    std::string path;
    std::optional<format::ConusFile> file;
    std::optional<codec::SamplingMap> map;
    std::string error;  // empty when loaded; names the file (aboutFile)
    bool ok() const { return file.has_value() && map.has_value(); }
    // Source size (the conventional frame), falling back to the CoNUS image's.
    int sourceWidth() const;
    int sourceHeight() const;
};

// The CoNUS file at `path`; with `foci`, the picture at `path` (PNG, JPEG, EXR, ...) as `conus
// encode --focus` writes it (encodedPicture).
Document loadDocument(const std::string& path, std::span<const codec::Focus> foci = {});

// The picture at `path` encoded through the map `conus encode --focus` gives `foci` on it, at the
// default size (codec::defaultConusSize): codec::budgetedFociMap with the encode's defaults (the
// foci on the picture's own detail, k held to the default frame-loss budget, the encode fitted),
// its confirming encode kept where it was of the map kept. Throws conus::Error.
format::ConusFile encodedPicture(const std::string& path, std::span<const codec::Focus> foci);

// `message` about the file at `path`, naming it once: as it is when it names the file already
// (the readers' messages do), else after "path: ".
std::string aboutFile(const std::string& path, const std::string& message);

// The uniform baseline in the CoNUS file at `path` (what `conus uniform` wrote: an identity map, so
// its image is the area-downsampled source), reconstructed through its map at its own size, for
// --uniform. Throws conus::Error like readConusFile.
Image uniformBaseline(const std::string& path);

}  // namespace conus::viewer
