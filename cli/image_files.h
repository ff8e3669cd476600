// What every command shares for ordinary image files: reading sources (colour space, EXIF
// orientation, NaN repair, which part) and writing pictures (bits, exposure, tone map), each a
// progress stage with its warnings. The files themselves go through conus::imageio.
#pragma once

#include <initializer_list>
#include <string>

#include "conus/imageio/image_file.h"

namespace CLI {
class App;
}

namespace conus::cli {

// --input-colorspace's value that takes the colour space from the file.
inline constexpr const char* kFromTheFile = "auto";

struct SourceOptions {
    std::string colorspace = kFromTheFile;  // or a Transfer's name
    bool noAutoOrient = false;
    std::string fixNonFinite = enumName(imageio::NonFiniteRepair::Keep);
    std::string part;                   // a part of a multi-part file, by name or index
};

// --input-colorspace, --no-auto-orient, --fix-nonfinite and --part.
void addSourceOptions(CLI::App& command, SourceOptions& options);

// Reads a picture (a progress stage), says which part of a multi-part file it took, and warns
// about NaN/Inf values it kept.
imageio::ImageFile readSource(const std::string& path, const SourceOptions& options, bool keepCodes = false);  // ReadOptions::keepCodes

// Reads a data image (importance map, DEM): raw values, never converted, upright.
Image readData(const std::string& path);

// An --importance argument: a rule's name ("detail", "faces": codec/builders/importance.h) applied to
// `picture` as a display shows it, or the path of an importance image (readData). `picture` may be
// empty for a path.
Image importanceFrom(const std::string& source, const Image& picture);

struct PictureOptions {
    std::string bits;  // "", 8, 16, half, float
    double exposure = 0;
    std::string toneMap = enumName(ToneMap::None);
};

// --bits, --exposure and --tonemap.
void addPictureOptions(CLI::App& command, PictureOptions& options);

// The write options for a picture of a source encoded as `source` (null: unknown).
imageio::WriteOptions writeOptionsOf(const PictureOptions& options, const SourceEncoding* source);

// Checks before the work that `path` can take such a picture (its extension, its bits, not one
// of `inputs`); throws conus::Error(InvalidArgument).
void checkPictureOutput(const std::string& path, const imageio::WriteOptions& options,
                        std::initializer_list<std::string> inputs = {});

// Writes a picture (a progress stage), warning when it holds NaN or infinite values.
void writePicture(const std::string& path, const Image& image, const imageio::WriteOptions& options = {});

// Writes a picture drawn for people (heat maps, comparison strips with labels) whose values are
// already display-encoded.
void writeDrawing(const std::string& path, const Image& image);

}  // namespace conus::cli
