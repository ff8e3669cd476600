// The perspective ground-plane map of the paper's CoNUS height fields (section 4, Figure 5): an
// analytic map whose sampling rate falls with the distance from a viewer standing at the middle of
// the bottom edge of the field, looking across it (toward v = 0).
//
// Geometry (ground units, only ratios matter): the field is a rectangle on the ground, its bottom
// edge (v = 1) at horizontal distance `near` from the viewer, its top edge (v = 0) at `far`; the
// eye is `eyeHeight` above the ground. Its width is what the horizontal field of view `fovDegrees`
// spans at the far edge, so far away the map is the viewer's own perspective camera.
// - Rows: a planar pinhole camera pitched down so that the near edge lands on the bottom image row
//   and the far edge on the top row; v_d is the camera's image row of the ground point: the
//   conventional perspective projection of the ground plane, rows spaced further apart with distance.
// - Columns: within a row, the viewing angle atan(x / z_cam) normalized by the angle of the field's
//   edge, so each row covers the full width (boundary to boundary) and, near the viewer, spends
//   more samples on the centre line. z_cam is the ground point's depth along the camera axis.
// - Rows given as a profile instead (`rows`, what the height-field encoder fits to a terrain, see
//   groundRowsForTerrain): v_d is the piecewise-linear function through (k / K, rows[k]); the
//   columns are unchanged. A terrain's mountains stand up into the view where the plane lies flat,
//   so the planar rows starve the far field.
// The map sends the unit square onto itself, each edge onto itself, is injective, and has an exact
// inverse groundUndistort (closed form, or per segment of the profile).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"

namespace conus::codec {

struct GroundParams {
    double eyeHeight = 0.25;  // > 0, eye above the ground
    double near = 0.0;        // >= 0, distance of the field's bottom edge (v = 1)
    double far = 1.0;         // > near, distance of the field's top edge (v = 0)
    double fovDegrees = 60.0;  // in (0, 170): horizontal field of view at the far edge
    // Empty: the planar pinhole rows. Else v_d at v = k / K for k = 0..K (K >= 1, at most
    // map_rules::kMaxGroundRows): 0 first, 1 last, strictly increasing.
    std::vector<double> rows{};
};

// Throws conus::Error(InvalidArgument) naming the parameter out of range.
void checkGroundParams(const GroundParams& params);

// Eq. 1 of the ground map: undistorted (ground) p -> distorted (CoNUS image); p clamped to [0,1]^2.
glm::dvec2 groundDistort(const GroundParams& params, glm::dvec2 p);
// Its exact inverse, closed form.
glm::dvec2 groundUndistort(const GroundParams& params, glm::dvec2 pd);

// The map on a columns x rows grid (each node = groundDistort of its undistorted position).
SamplingMap buildGroundMap(const GroundParams& params, int columns, int rows);

// Analytic parameters for the file: kind "ground", scalars eyeHeight, near, far, fovDegrees, and
// the row profile when there is one.
format::AnalyticMap toAnalytic(const GroundParams& params);
// Throws conus::Error(InvalidArgument) for another kind or a missing / out-of-range scalar.
GroundParams groundFromAnalytic(const format::AnalyticMap& analytic);

}  // namespace conus::codec
