// CoNUS height fields (paper sections 3.2 and 4, Figure 5): a terrain (heights in metres plus a
// colour) sampled orthogonally to the base plane through the perspective ground map of
// ground_map.h, so that the sampling rate falls with the distance from a viewer standing at the
// middle of the field's bottom edge. The server encodes (encodeHeightField); the client undistorts
// the CoNUS image back into a 3-D triangle mesh (undistortHeightField) and renders frames near the
// viewer (conus::renderers::renderTerrain). A uniform height field of the same sample count is the baseline.
//
// World frame of every Mesh (metres): x to the right (x = u * width), y up (y = height above the
// base plane), z toward the viewer (z = v * depth): the far edge (v = 0) lies at z = 0, the near
// edge (v = 1) at z = depth, and the viewer of the ground map stands at (width / 2, eyeHeight,
// depth + near) looking toward -z. The field's size in metres is fieldExtent(GroundParams): the
// ground parameters are read as metres (the map itself only needs their ratios).
//
// Shared rules: DEMs and colours are Image, row 0 at the far edge (v = 0, the image-plane
// convention), heights in one channel named "Z" (or the only channel), colours in "R","G","B"
// of the same size; sizes are checked (conus::Error InvalidArgument / LimitExceeded); threads = 0
// uses every core; nothing is printed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/builders/ground_map.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "conus/core/enum_names.h"
#include "conus/core/error.h"
#include "conus/core/mesh.h"
#include "conus/core/image.h"

namespace conus::codec {

// ---- Procedural terrain (the demo and the tests) -------------------------------------------

struct TerrainOptions {
    int width = 512, height = 512;  // DEM samples
    std::uint32_t seed = 1;         // same seed, same terrain, at any size
    double reliefMetres = 600.0;    // heights span about [0, reliefMetres]
    double features = 6.0;          // base wavelengths across the field (larger: more mountains)
    int octaves = 9;
    double ridges = 0.6;  // 0: rolling fBm hills, 1: sharp ridged mountains
};

// fBm of gradient noise blended with ridged noise, one channel "Z" in metres (>= 0). The terrain is
// a function of (u, v) in [0,1]^2, so two sizes of the same seed sample the same landscape.
Image generateTerrain(const TerrainOptions& options);
// The terrain a DEM argument "procedural[:SIZE[:SEED]]" names (SIZE x SIZE samples, SEED as
// TerrainOptions::seed; the defaults where left out), or none for any other text (a file's name).
// Throws InvalidArgument past kMaxDemSamples samples.
std::optional<TerrainOptions> proceduralTerrain(const std::string& source);

// Colour ramp by height (water-green lowlands, brown slopes, grey rock, snow on the highest) and
// slope (steep faces turn to rock), RGB in [0,1]. `extent` is the field's size in metres (width,
// depth), which turns height differences into slopes; the ramp spans the DEM's own min..max.
Image terrainColours(const Image& heights, glm::dvec2 extent);

// A DEM's colour in linear light, what `heightfield encode` and `bake relief` give the field:
// `texture` (linear light, however read; `textureName` names it in errors) at the DEM's size,
// area-downsampled when larger and refused when smaller (InvalidArgument); with no texture, the
// ramp of terrainColours taken as display colours (sRGB) and made linear.
Image demColour(const Image& heights, glm::dvec2 extent, std::optional<Image> texture = std::nullopt, const std::string& textureName = "");

// ---- Encode (server) -----------------------------------------------------------------------

// Width and depth in metres of the field a ground map covers: (2 * half width at the far edge,
// far - near).
glm::dvec2 fieldExtent(const GroundParams& params);
// The field of view (degrees) that makes fieldExtent(...).x equal `width` for the other parameters;
// throws conus::Error(InvalidArgument) when no fov in (0, 170) does.
double fovForFieldWidth(double eyeHeight, double near, double far, double width);

// A terrain's viewer in metres as a user gives it (`conus heightfield encode`): far and the field of
// view 0 until given.
struct TerrainViewer {
    double eyeHeight = 150, near = 200, far = 0, fovDegrees = 0;
};
// The ground map a terrain of `fieldMetres` (width, depth; 0 where its cell spacing is unknown) is
// seen through: far, where not given, near + the field's depth, else 6000; the field of view, where
// not given, the one that spans the field's width at far (fovForFieldWidth), else 60 degrees.
GroundParams groundForField(const TerrainViewer& viewer, glm::dvec2 fieldMetres);

// The ground map's rows for a terrain (GroundParams::rows): each band of depth gets rows in
// proportion to the screen rows it covers for the ground map's viewer (eyeHeight above the DEM at
// the middle of the near edge), its hidden parts left out (a horizon sweep along 128 rays), at most
// the DEM's own row rate and at least a quarter of the uniform rate. The planar rows give a band
// of mountains far away the few rows that flat ground would cover there. Empty when the DEM has
// nothing to see (the planar rows then stay).
std::vector<double> groundRowsForTerrain(const Image& heights, const GroundParams& ground, int imageRows);

// How a height field's map spends its rows on depth: fitted to the terrain (groundRowsForTerrain)
// or the planar pinhole rows (the paper's perspective ground plane).
enum class GroundRows { Terrain, Planar };
constexpr auto enumNameTable(GroundRows) {
    return makeEnumNameTable<GroundRows>("rows", {{GroundRows::Terrain, "terrain"}, {GroundRows::Planar, "planar"}});
}

struct HeightFieldOptions {
    GroundParams ground;         // with no row profile: fitted to the terrain when fitRows
    bool fitRows = true;         // the rows by groundRowsForTerrain (false: the planar pinhole rows)
    int width = 0, height = 0;  // CoNUS image size
    int mapGrid = 129;          // nodes per side of the map stored in the file
    std::string units = "m";
    int threads = 0;
    ProgressFn progress;
};

// The CoNUS height field: channels R,G,B,Z (Z = height above the base plane, FLOAT in the file),
// dataKind HeightField, depth kind Height with `units` and the range of Z, the ground map on a
// mapGrid x mapGrid grid plus its analytic parameters. Colour and height are footprint-filtered
// by encodeImage. The samples are taken through a map grid as fine as the CoNUS image (not the
// coarse stored grid), so each sample lies where the exact groundUndistort puts it to a small
// fraction of a pixel, and the client may undistort analytically.
format::ConusFile encodeHeightField(const Image& heights, const Image& colour,
                                    const HeightFieldOptions& options);

// The same through any sampling map (a relief asset's foci or importance map, relief.h): the map
// is sampled and stored as it is, without analytic parameters.
format::ConusFile encodeHeightField(const Image& heights, const Image& colour, const SamplingMap& map, int width,
                                    int height, const std::string& units = "m", int threads = 0);

// The baseline: the DEM area-downsampled to width x height (an identity map, no analytic
// parameters), with the same channels and depth attributes. width x height equal to the DEM's
// size gives the full-resolution reference.
format::ConusFile uniformHeightField(const Image& heights, const Image& colour, int width, int height,
                                     const std::string& units = "m", int threads = 0);

// ---- Undistort (client) --------------------------------------------------------------------

// A conus::Mesh (core/mesh.h) in the world frame above: colours RGB, normals per vertex
// (area-weighted face normals, y > 0 up), triangles counter-clockwise seen from above (+y).
// One vertex per CoNUS pixel at its undistorted ground position, plus a ring of border vertices on
// the field's edges (values of the nearest pixel) so the mesh covers the whole field; two
// triangles per quad of neighbouring vertices (the CoNUS image is a regular grid). Undistorts with
// the exact analytic groundUndistort when the file has ground parameters, else with the grid.
// Needs a Z channel; colour is R,G,B when present, else grey.
Mesh undistortHeightField(const format::ConusFile& file, glm::dvec2 extent);
// The same with the extent from the file's ground parameters; throws conus::Error(InvalidArgument)
// when it has none (a uniform field: give the extent).
Mesh undistortHeightField(const format::ConusFile& file);

// Height of the file's field at ground (u, v), bilinear in the CoNUS image through the map (for
// placing a camera above the ground).
double heightAt(const format::ConusFile& file, glm::dvec2 ground);

}  // namespace conus::codec
