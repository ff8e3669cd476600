// Uniform edge subdivision for the GPU mesh encoder (paper, section 3.2): Equation 1 is bilinear
// in each map cell, so a straight edge becomes a curve while the rasterizer draws the chord
// between its distorted ends. The renderer's default follows the bend on the GPU (the tessellation
// stages, renderers/mesh_render.h); this is the CPU alternative, `conus render mesh --max-edge`:
// every edge longer than a bound in undistorted map cells is split, where an edge from image
// position a to b (the camera's projection, before Eq. 1) spans |((b-a).u * (columns-1),
// (b-a).v * (rows-1))| cells. Edges with an end at or behind the near plane of a perspective
// camera are not measured (the rasterizer clips them) and never split, and the result is
// crack-free: an edge shared by two triangles is split once and both use the same new vertex
// (world-space midpoint; normals, colours and UVs interpolated, normals renormalized); a triangle
// with one, two or three split edges becomes two, three or four. The texture is kept.
#pragma once

#include <cstdint>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"
#include "conus/core/mesh.h"

namespace conus::codec {

inline constexpr std::int64_t kMaxSubdividedTriangles = std::int64_t{1} << 24;

struct SubdivideOptions {
    std::int64_t maxTriangles = kMaxSubdividedTriangles;  // cap on the result
};

// The longest projected edge of `mesh` in map cells (0 for a mesh none of whose edges is measured).
double longestProjectedEdge(const Mesh& mesh, const Camera& camera, const SamplingMap& map);

// `mesh` split until no projected edge spans more than `maxEdge` cells. Throws
// conus::Error(InvalidArgument) for maxEdge <= 0 or a bad mesh, LimitExceeded when the result
// would pass options.maxTriangles.
Mesh subdivideForMap(const Mesh& mesh, const Camera& camera, const SamplingMap& map, double maxEdge,
                     const SubdivideOptions& options = {});

}  // namespace conus::codec
