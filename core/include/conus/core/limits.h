// The resource limits of CoNUS, stated once. Every reader checks a size that comes from a file (or
// a command line) against these, in 64-bit arithmetic, before it allocates; `conus info --limits`
// prints them and spec/conus-format.md ("Limits") lists the same values. A caller may tighten them
// through a Limits value; the constants are the defaults.
// Standard types only, so that every library, the CLI and the Python module can include it.
#pragma once

#include <array>
#include <cstdint>

namespace conus {

// Images: every image any CoNUS library allocates (sources, CoNUS images, decoded frames).
inline constexpr int kMaxImageSide = 1 << 16;                            // pixels a side
inline constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 30;  // width * height
inline constexpr int kMaxChannels = 64;                                  // channels of a CoNUS image
inline constexpr std::int64_t kMaxTilePixels = std::int64_t{1} << 24;   // pixels of one tile of a tiled part

// Sampling maps: nodes per side (spec V7) and in all.
inline constexpr int kMinMapSide = 2;
inline constexpr int kMaxMapSide = 4097;
inline constexpr std::int64_t kMaxMapNodes = std::int64_t{kMaxMapSide} * kMaxMapSide;
// Nodes per side a map may have for its image: kMapNodesPerPixel a pixel along the image's longer
// side, plus one, and kMapSideAlways whatever the image (the largest grid a builder makes by
// default); map_rules.h's maxSideForImage.
inline constexpr int kMapNodesPerPixel = 4;
inline constexpr int kMapSideAlways = 129;

// File headers: bytes of one attribute's value, and of all attribute values of one part.
inline constexpr std::int64_t kMaxAttributeBytes = std::int64_t{1} << 20;
inline constexpr std::int64_t kMaxHeaderBytes = std::int64_t{4} << 20;

// The inverse map's index (SamplingMap::undistort): at most kIndexBytesPerCell per map cell plus
// kIndexBytesBase, and never more than kMaxIndexBytes, whatever the map's shape.
inline constexpr std::int64_t kIndexBytesPerCell = 128;
inline constexpr std::int64_t kIndexBytesBase = std::int64_t{64} << 10;
inline constexpr std::int64_t kMaxIndexBytes = std::int64_t{512} << 20;

// Memory for one decode: the CoNUS image's pixels as float plus the output frame's (and the
// picture writer's copy of the frame, in `conus decode`).
inline constexpr std::int64_t kMaxDecodeBytes = std::int64_t{8} << 30;
// Memory for one encode: the source picture and the CoNUS image, as float.
inline constexpr std::int64_t kMaxEncodeBytes = std::int64_t{8} << 30;

// Scene files (sceneio, the height-field readers): what one file may make a reader hold.
inline constexpr std::int64_t kMaxMeshFileBytes = std::int64_t{1} << 30;  // bytes of one mesh file
inline constexpr std::int64_t kMaxMeshTriangles = std::int64_t{1} << 24;  // triangles after triangulation
inline constexpr std::int64_t kMaxMeshVertices = std::int64_t{1} << 25;   // vertices after merging meshes
inline constexpr std::int64_t kMaxNamedFileBytes = std::int64_t{1} << 30;  // one file a scene file names
inline constexpr int kMaxVolumeSide = 1 << 14;                            // volume samples along one axis
inline constexpr std::int64_t kMaxVolumeVoxels = std::int64_t{1} << 28;  // volume samples in all (1 GiB as float)
// A volume read: its samples as float plus the reader's own decoded buffer of the file's type.
inline constexpr std::int64_t kMaxVolumeReadBytes = std::int64_t{2} << 30;
// Steps of one volume ray, per sample along the volume's sides (width + height + depth).
inline constexpr std::int64_t kMaxRayStepsPerSample = 16;
// Height samples of one elevation model (.npy, .npz, image, procedural).
inline constexpr std::int64_t kMaxDemSamples = std::int64_t{1} << 26;
// A scene's node tree: nodes along one path from a root, and nodes once every instance is
// expanded (a node shared by several parents counts once per path to it). Assimp recurses along
// the tree and copies each shared node once per parent.
inline constexpr int kMaxSceneDepth = 256;
inline constexpr std::int64_t kMaxSceneNodes = std::int64_t{1} << 20;
// Nesting of a text scene file's structure (glTF's JSON arrays and objects, COLLADA's and X3D's
// XML elements): the parsers Assimp uses recurse once per level.
inline constexpr int kMaxMarkupDepth = 512;
// Scans of a progressive JPEG: each is a pass over the whole image (libjpeg's progressive
// pictures have 10 or fewer).
inline constexpr int kMaxJpegScans = 100;
// Surfaces along the average ray of a CPU mesh render (the CoNUS ray cast and its layers, the
// reflection frame's eye and reflected rays), probed before the render: a ray must test every
// surface stacked in front of its first hit, so a mesh of many overlapping copies of one triangle
// costs each ray as many tests as copies, whatever the acceleration structure (2^17 copies: over a
// minute at 512x512). A GL render shades every copy at each pixel it covers: there the bound is
// on the surfaces the mesh stacks over any region, whatever the view (codec/mesh/overdraw.h).
// Closed models show a handful.
inline constexpr int kMaxMeshOverlap = 256;

// The caps a reader applies; a caller may lower any of them (never raise them past the constants:
// the constants are also what the format's own rules allow).
struct Limits {
    std::int64_t maxPixels = kMaxImagePixels;             // CoNUS image pixels
    int maxMapSide = kMaxMapSide;                         // sampling-map nodes per side
    int maxChannels = kMaxChannels;                       // CoNUS image channels
    std::int64_t maxAttributeBytes = kMaxAttributeBytes;  // one attribute value
    std::int64_t maxHeaderBytes = kMaxHeaderBytes;        // all attribute values of one part
    std::int64_t maxDecodeBytes = kMaxDecodeBytes;        // CoNUS image as float + output frame
};

// One limit as `conus info --limits` prints it and the spec lists it.
struct LimitEntry {
    const char* name;     // JSON key
    std::int64_t value;
    const char* unit;     // "pixels", "bytes", ...
    const char* meaning;  // one line
};

inline constexpr std::array<LimitEntry, 30> limitTable() {
    return {{
        {"imageSide", kMaxImageSide, "pixels", "width or height of any image (CoNUS image, source, decoded frame)"},
        {"imagePixels", kMaxImagePixels, "pixels", "width x height of any image"},
        {"channels", kMaxChannels, "channels", "channels of a CoNUS image"},
        {"tilePixels", kMaxTilePixels, "pixels", "pixels of one tile of a tiled `conus` part"},
        {"mapSideMin", kMinMapSide, "nodes", "sampling-map nodes per side, at least"},
        {"mapSide", kMaxMapSide, "nodes", "sampling-map nodes per side, at most"},
        {"mapNodes", kMaxMapNodes, "nodes", "sampling-map nodes in all"},
        {"mapNodesPerPixel", kMapNodesPerPixel, "nodes", "sampling-map nodes per side per pixel of the image's longer side, plus one"},
        {"mapSideAlways", kMapSideAlways, "nodes", "sampling-map nodes per side allowed whatever the image's size"},
        {"attributeBytes", kMaxAttributeBytes, "bytes", "value of one header attribute"},
        {"headerBytes", kMaxHeaderBytes, "bytes", "attribute values of one part's header"},
        {"indexBytesPerCell", kIndexBytesPerCell, "bytes", "inverse-map index per map cell (plus indexBytesBase)"},
        {"indexBytesBase", kIndexBytesBase, "bytes", "inverse-map index, fixed allowance"},
        {"indexBytes", kMaxIndexBytes, "bytes", "inverse-map index in all"},
        {"decodeBytes", kMaxDecodeBytes, "bytes", "one decode: CoNUS image as float plus the output frame"},
        {"encodeBytes", kMaxEncodeBytes, "bytes", "one encode: the source picture and the CoNUS image as float"},
        {"meshFileBytes", kMaxMeshFileBytes, "bytes", "one mesh file"},
        {"meshTriangles", kMaxMeshTriangles, "triangles", "triangles of one mesh after triangulation"},
        {"meshVertices", kMaxMeshVertices, "vertices", "vertices of one mesh after merging its parts"},
        {"volumeSide", kMaxVolumeSide, "samples", "volume samples along one axis"},
        {"volumeVoxels", kMaxVolumeVoxels, "samples", "volume samples in all"},
        {"volumeReadBytes", kMaxVolumeReadBytes, "bytes", "one volume read: samples as float plus the reader's decoded buffer"},
        {"rayStepsPerSample", kMaxRayStepsPerSample, "steps", "steps of one volume ray per sample of width + height + depth"},
        {"demSamples", kMaxDemSamples, "samples", "height samples of one elevation model"},
        {"namedFileBytes", kMaxNamedFileBytes, "bytes", "one file a scene file names (glTF buffer, material library, NRRD data file)"},
        {"sceneDepth", kMaxSceneDepth, "nodes", "nodes along one path of a scene's node tree"},
        {"sceneNodes", kMaxSceneNodes, "nodes", "nodes of a scene once shared nodes are expanded (instancing)"},
        {"markupDepth", kMaxMarkupDepth, "levels", "nesting of a glTF's JSON or a COLLADA or X3D file's XML"},
        {"jpegScans", kMaxJpegScans, "scans", "scans of a progressive JPEG (each a pass over the image)"},
        {"meshOverlap", kMaxMeshOverlap, "surfaces", "surfaces along the average ray of a CPU mesh render (probed), or over any region of a GL-rendered mesh"},
    }};
}

}  // namespace conus
