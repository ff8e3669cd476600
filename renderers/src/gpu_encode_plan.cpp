// The GPU encoder's plan on the CPU (gpu_encode_plan_pvt.h): the mesh, the pyramid's layout, the tiles.
#include "gpu_encode_plan_pvt.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "conus/codec/image/encode.h"
#include "conus/core/error.h"

namespace conus::renderers {
namespace {

// Positions along one axis of the map at which the mesh has vertices: every node, plus `splits[i]`
// equal steps across cell column (or row) i. One count per whole column or row of cells keeps
// neighbouring cells' vertices shared, so the mesh has no cracks.
std::vector<double> meshAxis(const std::vector<int>& splits) {
    const int cells = static_cast<int>(splits.size());
    std::vector<double> out;
    for (int i = 0; i < cells; ++i)
        for (int k = 0; k < splits[i]; ++k) out.push_back((i + static_cast<double>(k) / splits[i]) / cells);
    out.push_back(1.0);
    return out;
}

// The crops of every level around core [x0, x1) x [y0, y1) of a width x height source: level 1 at
// the atlas's origin, levels 2.. stacked to its right.
Tile planTile(const Pyramid& pyramid, int margin, int x0, int y0, int x1, int y1) {
    Tile tile{x0, y0, x1, y1, {}, 1, 1, {}};
    const double width = pyramid.rects[0][2], height = pyramid.rects[0][3];
    int stackY = 0, stackWidth = 0;
    for (std::size_t level = 0; level < pyramid.rects.size(); ++level) {
        const int w = pyramid.rects[level][2], h = pyramid.rects[level][3];
        TileLevel crop;
        crop.x = std::max(0, static_cast<int>(std::floor(x0 * (w / width))) - margin);
        crop.y = std::max(0, static_cast<int>(std::floor(y0 * (h / height))) - margin);
        crop.width = std::min(w, static_cast<int>(std::ceil(x1 * (w / width))) + margin) - crop.x;
        crop.height = std::min(h, static_cast<int>(std::ceil(y1 * (h / height))) + margin) - crop.y;
        if (level >= 2) {
            crop.atlasX = tile.levels[1].width;
            crop.atlasY = stackY;
            stackY += crop.height;
            stackWidth = std::max(stackWidth, crop.width);
        }
        tile.levels.push_back(crop);
    }
    if (tile.levels.size() > 1) {
        tile.atlasWidth = tile.levels[1].width + stackWidth;
        tile.atlasHeight = std::max(tile.levels[1].height, stackY);
    }
    return tile;
}

// Splits [0, size) into `count` near-equal parts.
std::vector<int> splitAxis(int size, int count) {
    std::vector<int> cuts;
    for (int i = 0; i <= count; ++i) cuts.push_back(static_cast<int>((static_cast<long long>(size) * i) / count));
    return cuts;
}

}  // namespace


// Each map cell is split into sub-quads so the piecewise-linear mesh follows the bilinear cell:
// a cell of twist t = N00 - N10 - N01 + N11 (in CoNUS pixels) split s ways departs from its
// bilinear patch by at most |t| / (4 s^2), kept under kMaxBendPixels; and no sub-quad is longer
// than kMaxSubQuadPixels, so the per-triangle derivatives that size the filter follow the local
// Jacobian. Finer meshes cost llvmpipe dearly (tiny triangles shade whole 2x2 quads).
Mesh buildMesh(const codec::SamplingMap& map, int width, int height) {
    constexpr double kMaxBendPixels = 0.05;
    constexpr double kMaxSubQuadPixels = 8.0;
    // Bounds the mesh (memory and vertex work) for extreme maps; finer subdivision stops here.
    constexpr double kMaxMeshVertices = 4.0e6;
    const int n = map.columns(), m = map.rows();
    const auto pixels = [&](glm::vec2 d) { return std::hypot(double(d.x) * width, double(d.y) * height); };
    // Most splits per cell that keep the whole mesh under kMaxMeshVertices.
    const int maxSplits = static_cast<int>(std::max(1.0, std::sqrt(kMaxMeshVertices / (double(n - 1) * (m - 1)))));
    std::vector<int> columnSplits(n - 1, 1), rowSplits(m - 1, 1);
    for (int j = 0; j + 1 < m; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            const glm::vec2 n00 = map.node(i, j), n10 = map.node(i + 1, j), n01 = map.node(i, j + 1);
            const double twist = pixels(n00 - n10 - n01 + map.node(i + 1, j + 1));
            const double bend = std::ceil(std::sqrt(twist / (4.0 * kMaxBendPixels)));
            const auto splits = [&](double extent) {
                return std::clamp(static_cast<int>(std::max(bend, std::ceil(extent / kMaxSubQuadPixels))), 1, maxSplits);
            };
            columnSplits[i] = std::max(columnSplits[i], splits(std::max(pixels(n10 - n00), pixels(map.node(i + 1, j + 1) - n01))));
            rowSplits[j] = std::max(rowSplits[j], splits(std::max(pixels(n01 - n00), pixels(map.node(i + 1, j + 1) - n10))));
        }
    const std::vector<double> us = meshAxis(columnSplits), vs = meshAxis(rowSplits);

    Mesh mesh;
    const std::size_t nu = us.size(), nv = vs.size();
    const codec::FootprintField field(map);
    mesh.vertices.reserve(nu * nv * kVertexFloats);
    for (double v : vs)
        for (double u : us) {
            const glm::dvec2 d = map.distort({u, v});
            const glm::dmat2 f = field.inverseJacobian({u, v});
            const glm::dvec2 a = f[0] / double(width), b = f[1] / double(height);
            mesh.vertices.insert(mesh.vertices.end(), {float(d.x), float(d.y), float(u), float(v), float(a.x),
                                                       float(a.y), float(b.x), float(b.y)});
        }
    mesh.indices.reserve((nu - 1) * (nv - 1) * 6);
    for (std::size_t j = 0; j + 1 < nv; ++j)
        for (std::size_t i = 0; i + 1 < nu; ++i) {
            const auto k = static_cast<GLuint>(j * nu + i), right = k + 1, below = static_cast<GLuint>(k + nu);
            mesh.indices.insert(mesh.indices.end(), {k, right, below + 1, k, below + 1, below});
        }
    return mesh;
}

Pyramid pyramidLayout(int width, int height) {
    Pyramid p;
    p.rects.push_back({0, 0, width, height});
    int y = 0;
    while ((width > 1 || height > 1) && static_cast<int>(p.rects.size()) < kMaxPyramidLevels) {
        width = std::max(1, (width + 1) / 2);
        height = std::max(1, (height + 1) / 2);
        p.rects.push_back({0, y, width, height});
        p.atlasWidth = std::max(p.atlasWidth, width);
        y += height;
    }
    p.atlasHeight = y;
    return p;
}

// Tiling, for sources (or their pyramids) over the texture limit: the source is cut into tiles,
// and each tile is drawn from crops of every pyramid level around its core. The levels are the
// full image's (built once, at the CPU reference's sizes), so a crop's texels are the full
// pyramid's texels and a tiled pixel reads exactly what an untiled one would.
//
// A tap lies within half the filter's extent along each footprint edge of the pixel's centre, plus
// a texel for the bilinear filter; the finer of the two blended levels reaches furthest in its own
// texels. The margin every level's crop needs is the largest such reach over the mesh's vertices
// (codec::planFootprint on their footprints), with room for the interpolation in between:
// kMarginSlack of it plus kMarginTexels. Maps with long footprints get wide margins, most get a few
// texels.
constexpr double kMarginSlack = 1.25;
constexpr int kMarginTexels = 3;

int tileMargin(const Mesh& mesh, int width, int height, double uniform) {
    double reach = 0;
    for (std::size_t k = 0; k + kVertexFloats <= mesh.vertices.size(); k += kVertexFloats) {
        const float* f = &mesh.vertices[k + 4];
        const glm::dvec2 a(f[0] * double(width), f[1] * double(height)), b(f[2] * double(width), f[3] * double(height));
        const codec::FootprintPlan plan = codec::planFootprint(a, b, uniform);
        const double scale = std::ldexp(1.0, -static_cast<int>(plan.level));  // level sizes round up: no smaller
        const double rx = 0.5 * (std::abs(a.x) * plan.extent.x + std::abs(b.x) * plan.extent.y);
        const double ry = 0.5 * (std::abs(a.y) * plan.extent.x + std::abs(b.y) * plan.extent.y);
        reach = std::max(reach, std::max(rx, ry) * scale);
    }
    return static_cast<int>(std::ceil(kMarginSlack * reach)) + kMarginTexels;
}

// The tiles of the source: the largest near-square cores whose crops fit the limit.
std::vector<Tile> planTiles(const Pyramid& pyramid, int margin, int limit) {
    const int width = pyramid.rects[0][2], height = pyramid.rects[0][3];
    for (int core = std::max(1, limit - 2 * margin - 2);; core = std::max(1, core - std::max(1, core / 16))) {
        const std::vector<int> xs = splitAxis(width, (width + core - 1) / core);
        const std::vector<int> ys = splitAxis(height, (height + core - 1) / core);
        std::vector<Tile> tiles;
        bool fits = true;
        for (std::size_t j = 0; j + 1 < ys.size() && fits; ++j)
            for (std::size_t i = 0; i + 1 < xs.size() && fits; ++i) {
                tiles.push_back(planTile(pyramid, margin, xs[i], ys[j], xs[i + 1], ys[j + 1]));
                const Tile& t = tiles.back();
                fits = t.levels[0].width <= limit && t.levels[0].height <= limit && t.atlasWidth <= limit &&
                       t.atlasHeight <= limit;
            }
        if (fits) return tiles;
        if (core == 1)
            throw Error(ErrorCode::LimitExceeded, "encodeImageGpu: no tiling of the " + std::to_string(width) + "x" +
                                                      std::to_string(height) + " source fits the texture limit " +
                                                      std::to_string(limit));
    }
}

// The tile's core in normalized source coordinates, open-ended at the source's edges (pixels whose
// undistorted centre falls just outside [0, 1] belong to the edge tiles).
std::array<float, 4> tileCore(const Tile& tile, int width, int height) {
    constexpr float kFar = std::numeric_limits<float>::max();
    return {tile.x0 == 0 ? -kFar : float(double(tile.x0) / width), tile.y0 == 0 ? -kFar : float(double(tile.y0) / height),
            tile.x1 == width ? kFar : float(double(tile.x1) / width),
            tile.y1 == height ? kFar : float(double(tile.y1) / height)};
}

// The mesh's triangles whose undistorted bounding box meets the tile's core (the shader discards
// the pixels outside it): each pixel is drawn by exactly one tile, the one whose core holds its
// interpolated undistorted centre.
std::vector<GLuint> tileIndices(const Mesh& mesh, const std::array<float, 4>& core) {
    std::vector<GLuint> out;
    for (std::size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
        float u0 = std::numeric_limits<float>::max(), v0 = u0, u1 = -u0, v1 = -u0;
        for (int c = 0; c < 3; ++c) {
            const float* vertex = &mesh.vertices[std::size_t(mesh.indices[k + c]) * kVertexFloats];
            u0 = std::min(u0, vertex[2]);
            u1 = std::max(u1, vertex[2]);
            v0 = std::min(v0, vertex[3]);
            v1 = std::max(v1, vertex[3]);
        }
        constexpr float kSlack = 1e-5f;  // interpolation may stray a rounding error past the vertices
        if (u1 + kSlack >= core[0] && u0 - kSlack <= core[2] && v1 + kSlack >= core[1] && v0 - kSlack <= core[3])
            out.insert(out.end(), mesh.indices.begin() + k, mesh.indices.begin() + k + 3);
    }
    return out;
}

}  // namespace conus::renderers
