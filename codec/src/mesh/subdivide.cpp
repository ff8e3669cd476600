// Edge subdivision for the GPU mesh encoder (subdivide.h). Each pass chooses the edges to split
// (by their two vertex indices, so both triangles of a shared edge agree), splits them at their
// world-space midpoints, and replaces each triangle by two, three or four; passes repeat until none
// is chosen. Midpoints are keyed by edge too, so a split edge has one new vertex.
#include "conus/codec/mesh/subdivide.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

// Projects every vertex once: image position and whether it lies in front of the near plane.
struct Projected {
    std::vector<glm::dvec2> uv;
    std::vector<char> measurable;
    glm::dvec2 pixels{1, 1};  // the image's size, for lengths in pixels
    std::vector<char> unchanged;  // per triangle: the last pass kept it as it was
};

Projected projectAll(const Mesh& mesh, const Camera& camera) {
    Projected out;
    out.uv.resize(mesh.positions.size());
    out.measurable.resize(mesh.positions.size());
    const bool perspective = camera.projection() == Projection::Perspective;
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::dvec3 p = camera.project(glm::dvec3(mesh.positions[i]));
        out.uv[i] = {p.x, p.y};
        out.measurable[i] = (!perspective || p.z > camera.near()) && std::isfinite(p.x) && std::isfinite(p.y);
    }
    return out;
}

// Length in map cells of the edge a-b, or -1 when it is not measured.
double cellLength(const Projected& projected, std::uint32_t a, std::uint32_t b, glm::dvec2 cells) {
    if (!projected.measurable[a] || !projected.measurable[b]) return -1;
    return glm::length((projected.uv[b] - projected.uv[a]) * cells);
}

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (std::uint64_t{a} << 32) | b;
}

glm::dvec2 cellsOf(const SamplingMap& map) { return {map.columns() - 1, map.rows() - 1}; }

// How far Equation 1 bends the image of a straight edge or the inside of a triangle away from what
// the rasterizer draws (the chord between distorted ends, the affine map of the distorted corners),
// in CoNUS pixels. The map is bilinear in each cell, so the departure is largest where the edge
// crosses a cell line (a kink) or inside a cell (a parabola's apex, near the middle of its piece);
// inside a triangle, at the map's nodes.
class BendMeter {
public:
    BendMeter(const SamplingMap& map, int width, int height) : m_map(map), m_pixels(width, height), m_cells(cellsOf(map)) {}

    // Equation 1 continued outside [0,1]^2 by translation, as the mesh vertex shader does.
    glm::dvec2 distort(glm::dvec2 p) const {
        const glm::dvec2 inside = glm::clamp(p, 0.0, 1.0);
        return m_map.distort(inside) + (p - inside);
    }

    double pixelLength(glm::dvec2 a, glm::dvec2 b) const { return glm::length((distort(b) - distort(a)) * m_pixels); }

    // The largest distance between distort(a + t (b - a)) and the chord's point at the same t.
    double edge(glm::dvec2 a, glm::dvec2 b) const {
        std::vector<double>& ts = m_ts;
        ts.assign({0.25, 0.5, 0.75});
        crossings(a.x, b.x, m_cells.x, ts);
        crossings(a.y, b.y, m_cells.y, ts);
        std::sort(ts.begin(), ts.end());
        const glm::dvec2 da = distort(a), db = distort(b);
        double worst = 0, previous = 0;
        auto at = [&](double t) {
            const glm::dvec2 off = (distort(a + t * (b - a)) - (da + t * (db - da))) * m_pixels;
            worst = std::max(worst, glm::length(off));
        };
        for (double t : ts) {
            at(t);
            at(0.5 * (previous + t));
            previous = t;
        }
        at(0.5 * (previous + 1));
        return worst;
    }

    // The largest distance, at the map's nodes inside the triangle a, b, c and at its centroid,
    // between the map and the affine map through the three distorted corners.
    double interior(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) const {
        const glm::dvec2 ab = b - a, ac = c - a;
        const double det = ab.x * ac.y - ab.y * ac.x;
        if (!(std::abs(det) > 1e-300)) return 0;
        const glm::dvec2 da = distort(a), dab = distort(b) - da, dac = distort(c) - da;
        auto departure = [&](glm::dvec2 p, glm::dvec2 dp) {
            const glm::dvec2 r = p - a;
            const double s = (r.x * ac.y - r.y * ac.x) / det, t = (ab.x * r.y - ab.y * r.x) / det;
            if (s < 0 || t < 0 || s + t > 1) return 0.0;
            return glm::length((dp - (da + s * dab + t * dac)) * m_pixels);
        };
        const glm::dvec2 centroid = (a + b + c) / 3.0;
        double worst = departure(centroid, distort(centroid));
        const glm::dvec2 lo = glm::clamp(glm::min(a, glm::min(b, c)), 0.0, 1.0), hi = glm::clamp(glm::max(a, glm::max(b, c)), 0.0, 1.0);
        const int i0 = int(std::ceil(lo.x * m_cells.x)), i1 = int(std::floor(hi.x * m_cells.x));
        const int j0 = int(std::ceil(lo.y * m_cells.y)), j1 = int(std::floor(hi.y * m_cells.y));
        for (int j = j0; j <= j1; ++j)
            for (int i = i0; i <= i1; ++i)
                worst = std::max(worst, departure({i / m_cells.x, j / m_cells.y}, glm::dvec2(m_map.node(i, j))));
        return worst;
    }

private:
    // The t in (0, 1) where x0 + t (x1 - x0) crosses a cell line (0, 1/cells, ..., 1) of one axis.
    static void crossings(double x0, double x1, double cells, std::vector<double>& ts) {
        const double g0 = std::clamp(std::min(x0, x1), 0.0, 1.0) * cells, g1 = std::clamp(std::max(x0, x1), 0.0, 1.0) * cells;
        if (!(x1 != x0)) return;
        for (double g = std::ceil(g0); g <= g1; ++g) {
            const double t = (g / cells - x0) / (x1 - x0);
            if (t > 0 && t < 1) ts.push_back(t);
        }
    }

    const SamplingMap& m_map;
    glm::dvec2 m_pixels, m_cells;
    mutable std::vector<double> m_ts;  // edge's scratch
};

}  // namespace

double longestProjectedEdge(const Mesh& mesh, const Camera& camera, const SamplingMap& map) {
    checkMesh(mesh, "longestProjectedEdge");
    const Projected projected = projectAll(mesh, camera);
    const glm::dvec2 cells = cellsOf(map);
    double longest = 0;
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e)
            longest = std::max(longest, cellLength(projected, mesh.indices[t + e], mesh.indices[t + (e + 1) % 3], cells));
    return longest;
}

namespace {

// The edges one pass splits, by edgeKey; each value becomes the edge's midpoint vertex.
using EdgeSplits = std::unordered_map<std::uint64_t, std::uint32_t>;

// The triangle's longest edge in the image (in world space when a corner has no image), ties
// broken by the edge key so that every triangle names the same one: edge e runs v[e] -> v[e+1].
int longestEdge(const Mesh& mesh, const Projected& projected, const std::uint32_t v[3]) {
    const bool imaged = projected.measurable[v[0]] && projected.measurable[v[1]] && projected.measurable[v[2]];
    int best = 0;
    std::pair<double, std::uint64_t> longest{-1.0, 0};
    for (int e = 0; e < 3; ++e) {
        const std::uint32_t a = v[e], b = v[(e + 1) % 3];
        const double length = imaged ? glm::length((projected.uv[b] - projected.uv[a]) * projected.pixels)
                                     : glm::distance(glm::dvec3(mesh.positions[a]), glm::dvec3(mesh.positions[b]));
        const std::pair<double, std::uint64_t> here{length, edgeKey(a, b)};
        if (here > longest) longest = here, best = e;
    }
    return best;
}

// Adds to `split` the longest edge of every triangle with a split edge, and again for the
// triangles across those, until none is missing: longest-edge bisection then needs no other
// pattern, and its triangles neither thin out nor loop.
void closeOverLongestEdges(const Mesh& mesh, const Projected& projected, EdgeSplits& split) {
    const std::size_t triangles = mesh.triangleCount();
    for (bool added = true; added;) {  // sweeps until none is added: as many as the longest chain
        added = false;
        for (std::size_t t = 0; t < triangles; ++t) {
            const std::uint32_t* v = &mesh.indices[t * 3];
            if (!split.count(edgeKey(v[0], v[1])) && !split.count(edgeKey(v[1], v[2])) && !split.count(edgeKey(v[2], v[0])))
                continue;
            const int r = longestEdge(mesh, projected, v);
            added |= split.emplace(edgeKey(v[r], v[(r + 1) % 3]), 0).second;
        }
    }
}

// Splits every edge in `split` at its world-space midpoint and replaces each triangle by two,
// three or four. A triangle looks its edges up by key, so both triangles of a shared edge use its
// one new vertex: no T-junction.
void splitEdges(Mesh& mesh, Projected& projected, const Camera& camera, EdgeSplits& split, const SubdivideOptions& options,
                const std::string& bound, bool bisectLongest) {
    const std::size_t triangles = mesh.triangleCount();
    std::vector<std::uint8_t> splitMask(triangles, 0);
    std::int64_t total = std::int64_t(triangles);
    for (std::size_t t = 0; t < triangles; ++t)
        for (int e = 0; e < 3; ++e)
            if (split.count(edgeKey(mesh.indices[t * 3 + e], mesh.indices[t * 3 + (e + 1) % 3]))) {
                splitMask[t] |= std::uint8_t(1u << e);
                ++total;  // 1 split: +1 triangle, 2: +2, 3: +3
            }
    if (total > options.maxTriangles)
        throw Error(ErrorCode::LimitExceeded, "subdivideForMap: " + bound + " needs more than " +
                                                  std::to_string(options.maxTriangles) + " triangles (" +
                                                  std::to_string(total) + " after this pass)");
    if (mesh.positions.size() + split.size() > std::size_t{UINT32_MAX})
        throw Error(ErrorCode::LimitExceeded, "subdivideForMap: too many vertices");
    const bool perspective = camera.projection() == Projection::Perspective;

    // New vertices, in a deterministic order (by the triangle and edge that first named them).
    for (auto& [key, id] : split) id = UINT32_MAX;
    for (std::size_t t = 0; t < triangles; ++t)
        for (int e = 0; e < 3; ++e) {
            if (!(splitMask[t] & (1u << e))) continue;
            const std::uint32_t a = mesh.indices[t * 3 + e], b = mesh.indices[t * 3 + (e + 1) % 3];
            std::uint32_t& id = split.at(edgeKey(a, b));
            if (id != UINT32_MAX) continue;
            id = std::uint32_t(mesh.positions.size());
            const glm::vec3 p = (mesh.positions[a] + mesh.positions[b]) * 0.5f;
            mesh.positions.push_back(p);
            const glm::vec3 n = mesh.normals[a] + mesh.normals[b];
            const float length = glm::length(n);
            mesh.normals.push_back(length > 0 ? n / length : mesh.normals[a]);
            if (!mesh.colours.empty()) mesh.colours.push_back((mesh.colours[a] + mesh.colours[b]) * 0.5f);
            if (!mesh.uvs.empty()) mesh.uvs.push_back((mesh.uvs[a] + mesh.uvs[b]) * 0.5f);
            const glm::dvec3 q = camera.project(glm::dvec3(p));
            projected.uv.emplace_back(q.x, q.y);
            projected.measurable.push_back((!perspective || q.z > camera.near()) && std::isfinite(q.x) && std::isfinite(q.y));
        }

    std::vector<std::uint32_t> indices;
    indices.reserve(std::size_t(total) * 3);
    projected.unchanged.assign(std::size_t(total), 0);
    auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) { indices.insert(indices.end(), {a, b, c}); };
    for (std::size_t t = 0; t < triangles; ++t) {
        const std::uint32_t v[3] = {mesh.indices[t * 3], mesh.indices[t * 3 + 1], mesh.indices[t * 3 + 2]};
        const std::uint8_t mask = splitMask[t];
        auto mid = [&](int e) { return split.at(edgeKey(v[e], v[(e + 1) % 3])); };
        if (bisectLongest && mask != 0) {
            // Longest-edge bisection (the split set holds every split triangle's longest edge):
            // halve the longest edge a-b towards c, then each half at its other split edge.
            const int r = longestEdge(mesh, projected, v);
            const std::uint32_t a = v[r], b = v[(r + 1) % 3], c = v[(r + 2) % 3], m = split.at(edgeKey(a, b));
            if (const auto bc = split.find(edgeKey(b, c)); bc != split.end()) {
                emit(m, b, bc->second);
                emit(m, bc->second, c);
            } else {
                emit(m, b, c);
            }
            if (const auto ca = split.find(edgeKey(c, a)); ca != split.end()) {
                emit(a, m, ca->second);
                emit(ca->second, m, c);
            } else {
                emit(a, m, c);
            }
            continue;
        }
        switch (mask) {
            case 0:
                projected.unchanged[indices.size() / 3] = 1;
                emit(v[0], v[1], v[2]);
                break;
            case 7: {  // all three: four triangles
                const std::uint32_t m0 = mid(0), m1 = mid(1), m2 = mid(2);
                emit(v[0], m0, m2);
                emit(m0, v[1], m1);
                emit(m2, m1, v[2]);
                emit(m0, m1, m2);
                break;
            }
            default: {
                // Rotate so the split edges come first: edge e runs v[e] -> v[e+1].
                int r = 0;
                const int count = (mask & 1) + ((mask >> 1) & 1) + ((mask >> 2) & 1);
                if (count == 1) {
                    while (!(mask & (1u << r))) ++r;
                } else {  // two: the unsplit edge is the third after rotation
                    while (mask & (1u << ((r + 2) % 3)) || !(mask & (1u << r))) ++r;
                }
                const std::uint32_t a = v[r], b = v[(r + 1) % 3], c = v[(r + 2) % 3];
                const std::uint32_t mab = split.at(edgeKey(a, b));
                if (count == 1) {
                    emit(a, mab, c);
                    emit(mab, b, c);
                } else {
                    const std::uint32_t mbc = split.at(edgeKey(b, c));
                    emit(mab, b, mbc);
                    // The quad a, mab, mbc, c: cut along its shorter diagonal.
                    const double d1 = glm::length(glm::dvec3(mesh.positions[a]) - glm::dvec3(mesh.positions[mbc]));
                    const double d2 = glm::length(glm::dvec3(mesh.positions[mab]) - glm::dvec3(mesh.positions[c]));
                    if (d1 <= d2) {
                        emit(a, mab, mbc);
                        emit(a, mbc, c);
                    } else {
                        emit(a, mab, c);
                        emit(mab, mbc, c);
                    }
                }
            }
        }
    }
    mesh.indices = std::move(indices);
}

// Splits in passes until `choose` (which fills the edges of one pass) names none.
template <class Choose>
Mesh subdivide(const Mesh& input, const Camera& camera, const SubdivideOptions& options, const std::string& bound,
               glm::dvec2 pixels, bool bisectLongest, Choose choose) {
    Mesh mesh = input;
    if (mesh.normals.empty()) computeVertexNormals(mesh);
    Projected projected = projectAll(mesh, camera);
    projected.pixels = pixels;
    projected.unchanged.assign(mesh.triangleCount(), 0);
    for (;;) {
        EdgeSplits split;
        choose(mesh, projected, split);
        if (split.empty()) return mesh;
        if (bisectLongest) closeOverLongestEdges(mesh, projected, split);
        splitEdges(mesh, projected, camera, split, options, bound, bisectLongest);
    }
}

}  // namespace

Mesh subdivideForMap(const Mesh& input, const Camera& camera, const SamplingMap& map, double maxEdge,
                     const SubdivideOptions& options) {
    checkMesh(input, "subdivideForMap");
    if (!(maxEdge > 0) || !std::isfinite(maxEdge))
        throw Error(ErrorCode::InvalidArgument, "subdivideForMap: the longest edge must be > 0 cells, got " + numberText(maxEdge));
    const glm::dvec2 cells = cellsOf(map);
    return subdivide(input, camera, options, "splitting edges to " + numberText(maxEdge) + " cells", {1, 1}, false,
                     [&](const Mesh& mesh, const Projected& projected, EdgeSplits& split) {
                         for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
                             for (int e = 0; e < 3; ++e) {
                                 const std::uint32_t a = mesh.indices[t + e], b = mesh.indices[t + (e + 1) % 3];
                                 if (cellLength(projected, a, b, cells) > maxEdge) split.emplace(edgeKey(a, b), 0);
                             }
                     });
}

BendMeasure measureBend(const Mesh& mesh, const Camera& camera, const SamplingMap& map, int width, int height) {
    checkMesh(mesh, "measureBend");
    const Projected projected = projectAll(mesh, camera);
    const BendMeter meter(map, width, height);
    BendMeasure out;
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
        const std::uint32_t v[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
        for (int e = 0; e < 3; ++e)
            if (projected.measurable[v[e]] && projected.measurable[v[(e + 1) % 3]])
                out.edges = std::max(out.edges, meter.edge(projected.uv[v[e]], projected.uv[v[(e + 1) % 3]]));
        if (projected.measurable[v[0]] && projected.measurable[v[1]] && projected.measurable[v[2]])
            out.interiors = std::max(out.interiors, meter.interior(projected.uv[v[0]], projected.uv[v[1]], projected.uv[v[2]]));
    }
    return out;
}

Mesh subdivideForBend(const Mesh& input, const Camera& camera, const SamplingMap& map, int width, int height,
                      double maxBend, const SubdivideOptions& options) {
    checkMesh(input, "subdivideForBend");
    if (!(maxBend > 0) || !std::isfinite(maxBend))
        throw Error(ErrorCode::InvalidArgument, "subdivideForBend: the largest bend must be > 0 pixels, got " + numberText(maxBend));
    const BendMeter meter(map, width, height);
    // Each edge measured once, whichever triangle asks in whichever pass; a triangle the last pass
    // kept is not measured again.
    std::unordered_map<std::uint64_t, bool> bent;
    return subdivide(input, camera, options, "following the map to " + numberText(maxBend) + " pixels", {width, height}, true,
                     [&](const Mesh& mesh, const Projected& projected, EdgeSplits& split) {
        // An edge shorter than the bound is never split: its image cannot stray much further.
        auto isBent = [&](std::uint32_t a, std::uint32_t b) {
            if (!projected.measurable[a] || !projected.measurable[b]) return false;
            const auto [it, added] = bent.emplace(edgeKey(a, b), false);
            if (added) {
                const glm::dvec2 pa = projected.uv[std::min(a, b)], pb = projected.uv[std::max(a, b)];
                it->second = meter.pixelLength(pa, pb) > maxBend && meter.edge(pa, pb) > maxBend;
            }
            return it->second;
        };
        for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
            if (projected.unchanged[t / 3]) continue;
            const std::uint32_t v[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
            bool any = false;
            for (int e = 0; e < 3; ++e)
                if (isBent(v[e], v[(e + 1) % 3])) {
                    split.emplace(edgeKey(v[e], v[(e + 1) % 3]), 0);
                    any = true;
                }
            if (any || !projected.measurable[v[0]] || !projected.measurable[v[1]] || !projected.measurable[v[2]]) continue;
            // Straight edges around a bent inside (a focus within one triangle): split the longest.
            if (meter.interior(projected.uv[v[0]], projected.uv[v[1]], projected.uv[v[2]]) <= maxBend) continue;
            const int r = longestEdge(mesh, projected, v);
            if (meter.pixelLength(projected.uv[v[r]], projected.uv[v[(r + 1) % 3]]) > maxBend)
                split.emplace(edgeKey(v[r], v[(r + 1) % 3]), 0);
        }
    });
}
}  // namespace conus::codec
