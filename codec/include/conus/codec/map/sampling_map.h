// The sampling map of the flexible pinhole camera (paper section 3.1, spec/ section 2): a grid of
// columns x rows nodes, node (i,j) at undistorted (i/(columns-1), j/(rows-1)) holding its distorted
// location. distort() is the paper's Equation 1 (bilinear interpolation of the nodes); undistort()
// is its exact inverse, O(1) per lookup through a bucket grid over the distorted plane.
//
// A SamplingMap is always valid: the constructor asks core/map_rules.h's isValidGrid (V7..V11:
// finite nodes in [0,1]^2, boundary nodes on their edge, every cell strictly convex with the
// identity's orientation) and throws conus::Error(InvalidMap) with format::validateGrid's words.
// Coordinates are normalized: u right, v down, origin top-left. Points outside [0,1]^2 are clamped.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "conus/core/fpc.h"
#include "conus/format/container.h"

namespace conus::codec {

// The grid distortion of the FPC (core/fpc.h): final, so direct calls are not virtual.
class SamplingMap final : public Distortion {
public:
    SamplingMap(int columns, int rows, std::vector<glm::vec2> nodes);
    static SamplingMap identity(int columns, int rows);
    static SamplingMap fromGrid(const format::GridNodes& grid);
    format::GridNodes toGrid() const;

    int columns() const { return m_columns; }
    int rows() const { return m_rows; }
    const std::vector<glm::vec2>& nodes() const { return m_nodes; }
    glm::vec2 node(int i, int j) const { return m_nodes[static_cast<std::size_t>(j) * m_columns + i]; }

    // Equation 1: undistorted (u,v) -> distorted (u_d,v_d).
    glm::dvec2 distort(glm::dvec2 p) const override;
    // The exact inverse of distort: distorted -> undistorted, to 1e-9. Its index is built on the
    // first call (thread-safe) and is bounded whatever the map's shape (limits.h: kIndexBytesPerCell
    // a cell plus kIndexBytesBase, at most kMaxIndexBytes); maps never undistorted never build it.
    glm::dvec2 undistort(glm::dvec2 pd) const override;
    // Bytes held by undistort's index (building it if needed): for tests and `conus info`.
    std::size_t indexBytes() const;
    // d distort / d p at undistorted p; column 0 is d/du, column 1 is d/dv.
    glm::dmat2 jacobian(glm::dvec2 p) const override;
    // Sampling density at undistorted p: det(jacobian). 1 everywhere for the identity; d means the
    // CoNUS image holds d times as many samples per unit area there as a uniform image.
    double density(glm::dvec2 p) const;
    // The same map on another grid (each new node = distort of its undistorted position). The
    // result is validated like any map.
    SamplingMap resampled(int columns, int rows) const;

    SamplingMap(const SamplingMap&);
    SamplingMap& operator=(const SamplingMap&);
    SamplingMap(SamplingMap&&) noexcept;
    SamplingMap& operator=(SamplingMap&&) noexcept;
    ~SamplingMap();

private:
    struct Index;      // bucket grid for undistort
    struct LazyIndex;  // builds it once, on first use
    const Index& index() const;

    int m_columns = 0;
    int m_rows = 0;
    std::vector<glm::vec2> m_nodes;
    std::vector<glm::dvec2> m_dnodes;  // the nodes in double: what distort and undistort compute with
    double m_invCellsX = 1.0, m_invCellsY = 1.0;
    std::unique_ptr<LazyIndex> m_lazy;
};

}  // namespace conus::codec
