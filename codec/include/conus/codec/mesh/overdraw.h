// What a rasterizer pays for a mesh whatever the view. Each triangle is shaded at every pixel it
// covers, in front of the nearest surface or behind it, so a mesh of many overlapping copies of a
// surface costs every pixel they cover one fragment per copy (2^17 near-copies of a triangle: 2^17
// fragments a pixel), which no depth test or acceleration structure avoids. A renderer whose
// camera moves (the viewer) cannot probe one view; this bound holds for all of them.
#pragma once

#include <string>

#include "conus/core/mesh.h"

namespace conus::codec {

// The grids meshOverdraw counts surfaces in: level L cuts a shadow's longer side into 2^L cells.
inline constexpr int kMeshOverdrawLevels = 10;

// The most surfaces the mesh stacks over a region, seen along any of 13 directions (the axes, the
// face and the body diagonals; any direction is within 35 degrees of one). Along each, every
// triangle's shadow is counted on the finest grid whose cells are at least its size (so its box
// meets 2 x 2 of them at most), its area spread evenly over its box; a cell's count is the area of
// its surfaces over the box their parts in it fill: the mean number of surfaces there, which a
// view zoomed on that box draws per pixel. One triangle counts 1/2 (a triangle fills half its
// box), a square 1, a closed model about 2 wherever it is seen; areas add up, so fine
// tessellation adds nothing, and copies stacked along a direction count together however far
// apart they lie. What can count less than it draws: triangles of very different sizes stacked
// (each size's grid is bounded, and small triangles cover little), a stack whose cell also holds
// other surfaces far from it (diluted at most about 8 times: those are as large as the cell's
// half), copies lined up along a direction far from all 13.
double meshOverdraw(const Mesh& mesh);

// Refuses (LimitExceeded, naming `what`) a mesh whose meshOverdraw passes kMaxMeshOverlap
// (limits.h): the GL renders check it before they upload the mesh, the viewer's whatever view.
void checkMeshOverdraw(const Mesh& mesh, const std::string& what);

}  // namespace conus::codec
