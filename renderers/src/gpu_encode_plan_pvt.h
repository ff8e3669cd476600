// Private: the GPU encoder's plan, made on the CPU before any GL call (gpu_encode_plan.cpp): the
// mesh that follows the map, the layout of the source's pyramid, and tiles for sources (or
// pyramids) over the texture limit.
#pragma once

#include <array>
#include <vector>

#include <glad/gl.h>

#include "conus/codec/map/sampling_map.h"

namespace conus::renderers {

constexpr int kVertexFloats = 8;

struct Mesh {
    // Per vertex: distorted x, y; undistorted u, v; the footprint (codec::FootprintField), as the
    // undistorted change per CoNUS pixel along x and along y.
    std::vector<float> vertices;
    std::vector<GLuint> indices;
};

// The map's mesh for a width x height CoNUS image: each cell split so that the piecewise-linear
// mesh follows the bilinear cell (gpu_encode_plan.cpp says how far).
Mesh buildMesh(const codec::SamplingMap& map, int width, int height);

// The encoder's source pyramid at the CPU reference's level sizes ((w + 1) / 2 each way, down to
// 1 x 1): level 0 is the source texture itself, levels 1.. are stacked in one RGBA32F atlas.
constexpr int kMaxPyramidLevels = 32;  // uLevelRect in encode.frag.glsl

struct Pyramid {
    std::vector<std::array<int, 4>> rects;  // per level: x, y in the atlas, width, height
    int atlasWidth = 0, atlasHeight = 0;
};

Pyramid pyramidLayout(int width, int height);

struct TileLevel {
    int x = 0, y = 0, width = 0, height = 0;  // the crop, in the full level's texels
    int atlasX = 0, atlasY = 0;               // where it sits in its texture
};

struct Tile {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the core, in source texels
    std::vector<TileLevel> levels;       // level 0 is its own texture; levels 1.. share an atlas
    int atlasWidth = 1, atlasHeight = 1;
    std::vector<GLuint> indices;  // the mesh triangles that may reach into the core
};

// The margin in texels every level's crop needs around a tile's core, for a width x height
// source encoded with uniform spacing `uniform` (gpu_encode_plan.cpp says why it suffices).
int tileMargin(const Mesh& mesh, int width, int height, double uniform);

// The tiles of the source: the largest near-square cores whose crops fit the limit; throws
// LimitExceeded when none does.
std::vector<Tile> planTiles(const Pyramid& pyramid, int margin, int limit);

// The tile's core in normalized source coordinates, open-ended at the source's edges (pixels whose
// undistorted centre falls just outside [0, 1] belong to the edge tiles).
std::array<float, 4> tileCore(const Tile& tile, int width, int height);

// The mesh's triangles whose undistorted bounding box meets the tile's core.
std::vector<GLuint> tileIndices(const Mesh& mesh, const std::array<float, 4>& core);

}  // namespace conus::renderers
