// The CoNUS container, version 1 (spec/conus-format.md): an OpenEXR multipart file with a `conus`
// part (the CoNUS image, an ordinary EXR image to any tool) and a `samplingmap` part (the grid of
// distorted node positions), plus attributes for analytic map parameters, camera, source size and
// data kind. This header is the whole model; no OpenEXR type appears here.
//
// Rules shared by the functions below:
// - writeConusFile validates first and writes nothing for an invalid file; it writes through
//   conus::AtomicFile (core/atomic_file.h), so no half-written file is ever left.
// - readConusFile reads regular files only. It checks every size against conus::Limits (limits.h)
//   before allocating, and the chunk tables against the file's size before committing memory for
//   pixels; it throws conus::Error: NotConus for an EXR without a `conus` part, Corrupt for a
//   damaged file or a broken V-rule, LimitExceeded for sizes beyond the limits, Io when the file
//   cannot be opened or is not a regular file. Messages are one line.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "conus/core/color.h"
#include "conus/core/error.h"
#include "conus/core/image.h"
#include "conus/core/limits.h"
#include "conus/core/camera.h"
#include "conus/format/names.h"
#include "conus/format/validation.h"

namespace conus::format {

inline constexpr int kFormatVersion = 1;
inline constexpr const char* kSoftwareName = "conus 1.0.0";  // the `software` attribute written by default
inline constexpr const char* kConusPartName = "conus";
inline constexpr const char* kMapPartName = "samplingmap";


// The sampling map's nodes: node (i,j), i the column, j the row, sits at undistorted
// (i/(columns-1), j/(rows-1)) and stores its distorted location (xy[2k], xy[2k+1]), k = j*columns+i.
struct GridNodes {
    int columns = 0;
    int rows = 0;
    std::vector<float> xy;
};

struct FocusParams {
    double u = 0, v = 0;  // centre, normalized image-plane coordinates
    double r = 0;         // radius as a fraction of the image width (circular in pixels)
    double k = 1;         // linear magnification at the centre relative to far context
};

// How a map was built, kept so the same map can be rebuilt and shown (focus outlines, ground
// plane). The grid in `samplingmap` is always the authority for decoding.
struct AnalyticMap {
    std::string kind;                       // a MapKind's name (names.h; spec/ lists the kinds)
    std::vector<FocusParams> foci;          // kind "foci"
    std::string composition;                // kind "foci": a FociComposition's name (names.h)
    std::map<std::string, double> scalars;  // other kinds' named parameters
    std::vector<float> groundRows{};        // kind "ground": the row profile, if any (conus:groundRows)

    bool is(MapKind k) const { return kind == enumName(k); }
};

// The camera as the file records it (rule V13): EXR's standard matrices and conus:projection, as
// read, so that the validator can report on them. toCamera() gives the camera model they describe.
struct CameraAttributes {
    std::string projection = enumName(Projection::Perspective);  // a Projection's name
    std::array<float, 16> worldToCamera{};    // row-major, as EXR's standard attribute (M44f)
    std::array<float, 16> worldToNDC{};
};
// The pinhole camera the attributes describe; conus::Error(Corrupt), naming V13, when they
// describe none (an unknown projection, a non-finite or singular matrix, matrices that disagree
// with the projection).
conus::Camera toCamera(const CameraAttributes& attributes);
CameraAttributes toAttributes(const conus::Camera& camera);

struct DepthInfo {
    DepthKind kind = DepthKind::None;
    std::string units = "";  // e.g. "m"
    float near = 0, far = 0;  // range of valid depths/heights
};

struct ConusFile {
    Image image;                         // the CoNUS image (channels incl. optional Z)
    PixelType pixelType = PixelType::Half;
    Compression compression = Compression::Zip;
    int sourceWidth = 0, sourceHeight = 0;  // size of the conventional frame it encodes
    DataKind dataKind = DataKind::Image;
    GridNodes map;
    std::optional<AnalyticMap> analytic;
    std::optional<CameraAttributes> camera;
    DepthInfo depth;
    // What the source picture held (its transfer, sample type, chromaticities, ICC profile, EXIF
    // and camera metadata), so that decode can give it back as it was. The pixels themselves are
    // linear light with associated alpha, or raw data when sourceEncoding.transfer is Raw.
    SourceEncoding sourceEncoding;
    std::string software;  // free text; the writer fills "conus <version>" when empty
};

void writeConusFile(const std::string& path, const ConusFile& file);
// Refuses (InvalidArgument) an output name that does not end in .exr (any case): a CoNUS file is
// an OpenEXR file, and a picture's extension would make readers expect a picture. The CLI and the
// Python package call it before any work.
void checkConusFileName(const std::string& path);
ConusFile readConusFile(const std::string& path, const Limits& limits = {});
// Everything readConusFile reads but the CoNUS image's pixels (what `conus info` and `validate`
// need): the image has its width, height and channels and no pixels. The same checks run, the
// chunk tables included, so a file this accepts does hold its pixel data's bytes.
ConusFile readConusHeader(const std::string& path, const Limits& limits = {});

// Every violated rule of the file at `path`, one CoNUS image or a reflection asset
// (reflection_asset.h), never throwing for bad content. With `readPixels`
// (the default) every chunk of pixel data is read and decompressed too, as readConusFile does, so
// a file that validates also reads; without, headers, the map and the chunk tables only.
ValidationReport validateConusFile(const std::string& path, const Limits& limits = {}, bool readPixels = true);
// Every violated rule of an in-memory file (structure, attributes, map geometry).
ValidationReport validateConusFile(const ConusFile& file);
// The sampling-map rules alone (node count, finite values, boundary, strictly convex cells with
// the identity's orientation), rule by rule in words; whether a grid is valid is decided by
// core/map_rules.h's isValidGrid, which this agrees with.
ValidationReport validateGrid(const GridNodes& grid);

}  // namespace conus::format
