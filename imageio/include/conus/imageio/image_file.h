// Ordinary image files (PNG, JPEG, TIFF, BMP, EXR, HDR, PPM, ... through OpenImageIO): the one
// place CoNUS reads and writes them. CoNUS containers go through conus::format instead.
//
// Rules shared by every function here:
// - Channels are placed by name, never by storage order (OpenEXR stores B,G,R): a display format
//   gets R,G,B(,A), or Y(,A) for grey, whatever order the image holds them in (1 to 64 channels).
// - Colour (core/color.h): images in memory hold linear light with associated alpha. Reading
//   converts display-referred files (8/16-bit, sRGB or untagged) to linear through OpenImageIO's
//   colour conversion (plain PNGs, read with libpng: the sRGB formula, within 1.4e-5 of it); linear and float files stay as they are; `raw` data is never converted.
//   Writing an integer format encodes sRGB again (or restores the source's encoding); float
//   formats stay linear. Only colour channels (R, G, B, Y) are converted; A, Z and others never.
// - Sizes are checked against the library limits before any pixel is allocated.
// - Writes go through conus::AtomicFile: checked to the last byte, then renamed into place.
// - Errors are conus::Error naming the user's path: Io for files that cannot be read or written,
//   LimitExceeded for sizes past the limits, InvalidArgument for requests a format cannot hold.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "conus/core/color.h"
#include "conus/core/display.h"
#include "conus/core/enum_names.h"
#include "conus/core/image.h"
#include "conus/core/limits.h"

namespace conus::imageio {

// What to do with NaN and infinite values found in a file.
enum class NonFiniteRepair {
    Keep,   // keep them (the reader reports how many it found)
    Black,  // replace them by 0
    Box3,   // replace them by the average of their finite 3x3 neighbours (oiiotool --fixnan box3)
};

constexpr auto enumNameTable(NonFiniteRepair) {
    return makeEnumNameTable<NonFiniteRepair>("non-finite repair", {{NonFiniteRepair::Keep, "keep"}, {NonFiniteRepair::Black, "black"},
                                                                    {NonFiniteRepair::Box3, "box3"}});
}

struct ReadOptions {
    std::optional<Transfer> colorspace;  // absent: from the file (float: linear; integer: sRGB unless tagged linear)
    bool autoOrient = true;              // apply the EXIF Orientation, so the frame is the one people see
    std::string part;                    // a part (subimage) by name or index; empty: the first
    NonFiniteRepair repair = NonFiniteRepair::Keep;
    Limits limits;  // maxPixels, maxChannels, maxAttributeBytes, maxHeaderBytes, maxDecodeBytes apply
    // A plain 8-bit sRGB PNG (one read without OpenImageIO) kept as its codes: ImageFile::codes
    // holds them and `image` only its size and channels (no pixels). Any other file reads as ever.
    bool keepCodes = false;
};

struct ImageFileInfo {
    std::string format;         // OpenImageIO's format name: "png", "jpeg", "openexr", ...
    SourceEncoding encoding;    // what the file held: transfer, sample type, ICC, metadata
    int parts = 1;              // subimages in the file
    int part = 0;               // the one read
    std::string partName;       // its name, when the file names its parts
    int orientation = 1;        // the file's EXIF orientation (1: upright)
    bool oriented = false;      // whether it was applied
    std::int64_t nonFinite = 0;  // NaN and infinite values found (before any repair)
};

struct ImageFile {
    Image image;
    ImageFileInfo info;
    // ReadOptions::keepCodes, where it applied: the 8-bit sRGB codes, interleaved as image's
    // channels; image.pixels is then empty.
    std::vector<std::uint8_t> codes;
};

// Reads `path` ("-": standard input). Refuses files that are not regular files.
ImageFile readImageFile(const std::string& path, const ReadOptions& options = {});

// What the pixel values of an image to be written are.
enum class PixelMeaning {
    Linear,   // linear light (decoded views, CoNUS images): encoded for display formats
    Display,  // already display-encoded sRGB (heat maps, pictures drawn for people): written as they are
    Raw,      // data: written as they are everywhere
};

struct WriteOptions {
    PixelMeaning meaning = PixelMeaning::Linear;
    // The sample type to write; absent: the source's where the format holds it (16-bit PNG stays
    // 16-bit), else the format's natural one (8 bits for PNG/JPEG, half for EXR, float for TIFF of
    // a linear source).
    std::optional<SampleType> sampleType;
    // The source the pixels came from: restores its encoding (a raw source stays raw, a linear
    // 16-bit PNG stays linear), its ICC profile and its metadata (EXIF, Make, Model, ...).
    const SourceEncoding* source = nullptr;
    DisplayOptions display;  // exposure (every format) and tone map (integer formats only)
};

// Writes `image` to `path`, its format chosen by the extension.
void writeImageFile(const std::string& path, const Image& image, const WriteOptions& options = {});

// Checks, before any work, that writeImageFile can write `path` with these options: a known
// extension, a sample type the format holds. Throws conus::Error(InvalidArgument).
void checkImageOutput(const std::string& path, const WriteOptions& options = {});

// The sample types a file format holds, for messages: "8 or 16 bits" and so on.
std::string sampleTypesOf(const std::string& path);

// NaN and infinite values in `image`.
std::int64_t countNonFinite(const Image& image);

// Replaces the NaN and infinite values of an image in memory as reading with that repair does.
void repairNonFinite(Image& image, NonFiniteRepair repair);

// Converts an image of display-encoded sRGB values (a picture drawn in memory) to linear light
// with associated alpha, as if it had been read from an 8-bit file.
void linearize(Image& image);

// A copy of `image` as a display shows it: alpha divided out, colour channels encoded to sRGB
// and clamped to [0,1], non-finite values 0. Through OpenImageIO where there is alpha; without it
// by a table of the sRGB curve, within 1e-6 of it, without loading OpenImageIO. For algorithms tuned on
// photographs as people see them (face detection, detail importance).
Image displayEncoded(const Image& image);

}  // namespace conus::imageio
