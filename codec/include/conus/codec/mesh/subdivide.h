// Offline edge subdivision for the GPU mesh encoder (paper, section 3.2): Equation 1 is bilinear
// in each map cell, so a straight edge becomes a curve while the rasterizer draws the chord
// between its distorted ends, and a triangle's inside moves by the affine map of its distorted
// corners. Splitting triangles where those depart from the map keeps the picture on the curves.
//
// Two rules choose the edges. subdivideForBend (the default of `conus mesh render`) splits only
// where the map bends: an edge whose image departs from its chord, or a triangle whose inside
// departs from its affine map, by more than a bound in CoNUS pixels; where the map is affine
// nothing is split. subdivideForMap splits every edge longer than a bound in undistorted map
// cells: an edge from image position a to b (the camera's projection, before Eq. 1) spans
// |((b-a).u * (columns-1), (b-a).v * (rows-1))| cells. Either way, edges with an end at or behind
// the near plane of a perspective camera are not measured (the rasterizer clips them) and never
// split, and the result is crack-free: an edge shared by two triangles is split once and both use
// the same new vertex (world-space midpoint; normals, colours and UVs interpolated, normals
// renormalized); a triangle with one, two or three split edges becomes two, three or four. The
// texture is kept.
#pragma once

#include <cstdint>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"
#include "conus/core/mesh.h"

namespace conus::codec {

inline constexpr std::int64_t kMaxSubdividedTriangles = std::int64_t{1} << 24;
inline constexpr double kDefaultMaxBend = 0.25;  // CoNUS pixels: `conus mesh render`'s --max-bend

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

// How far the map bends `mesh`'s picture in a width x height CoNUS image, in its pixels: the
// largest distance between the image of an edge and its chord (at the edge's crossings of the
// map's cell lines, the points halfway between them and its quarter points), and between the
// image of a triangle's inside and its corners' affine map (at the map nodes inside and the
// centroid). Outside [0,1]^2 the map continues by translation, as the vertex shader's does.
struct BendMeasure {
    double edges = 0, interiors = 0;
    double largest() const { return edges > interiors ? edges : interiors; }
};
BendMeasure measureBend(const Mesh& mesh, const Camera& camera, const SamplingMap& map, int width, int height);

// `mesh` split where the map bends it by more than `maxBend` pixels of a width x height image: an
// edge bent that far is split; a triangle with straight edges and a bent inside has its longest
// edge (in the image) split; an edge shorter than maxBend pixels in the image is never split. Throws
// conus::Error(InvalidArgument) for maxBend <= 0 or a bad mesh, LimitExceeded past
// options.maxTriangles.
Mesh subdivideForBend(const Mesh& mesh, const Camera& camera, const SamplingMap& map, int width, int height,
                      double maxBend, const SubdivideOptions& options = {});

}  // namespace conus::codec
