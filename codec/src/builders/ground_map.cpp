// The perspective ground-plane map: rows by a pitched pinhole camera (or a given profile), columns
// by normalized viewing angle; both invert exactly.
#include "conus/codec/builders/ground_map.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "conus/core/error.h"
#include "conus/core/map_rules.h"

namespace conus::codec {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMaxFov = 170.0;

// Everything the two directions need, derived once from the parameters.
struct Geometry {
    double h, nearZ, farZ;
    double pitch;   // camera axis angle below the horizon
    double tanPhi;  // tan of half the vertical field of view
    double cosPitch, sinPitch;
    double halfWidth;  // of the field, ground units

    explicit Geometry(const GroundParams& p) : h(p.eyeHeight), nearZ(p.near), farZ(p.far) {
        const double alphaNear = std::atan2(h, nearZ), alphaFar = std::atan2(h, farZ);
        pitch = 0.5 * (alphaNear + alphaFar);
        tanPhi = std::tan(0.5 * (alphaNear - alphaFar));
        cosPitch = std::cos(pitch);
        sinPitch = std::sin(pitch);
        halfWidth = zCam(farZ) * std::tan(0.5 * p.fovDegrees * kPi / 180.0);
    }
    double zCam(double z) const { return z * cosPitch + h * sinPitch; }  // > 0 for z >= 0
    double groundZ(double v) const { return nearZ + (1.0 - v) * (farZ - nearZ); }
};

// The profile's v_d at v, and its inverse (both piecewise linear, strictly increasing).
double profileRow(const std::vector<double>& rows, double v) {
    const int segments = static_cast<int>(rows.size()) - 1;
    const double t = v * segments;
    const int k = std::clamp(static_cast<int>(t), 0, segments - 1);
    return rows[std::size_t(k)] + (t - k) * (rows[std::size_t(k) + 1] - rows[std::size_t(k)]);
}

double profileInverse(const std::vector<double>& rows, double vd) {
    const int segments = static_cast<int>(rows.size()) - 1;
    const auto next = std::upper_bound(rows.begin() + 1, rows.end() - 1, vd);
    const int k = static_cast<int>(next - rows.begin()) - 1;
    const double a = rows[std::size_t(k)], b = rows[std::size_t(k) + 1];
    return (k + std::clamp((vd - a) / (b - a), 0.0, 1.0)) / segments;
}

}  // namespace

void checkGroundParams(const GroundParams& p) {
    // Negated comparisons so that NaN fails every check.
    if (!(p.eyeHeight > 0.0 && p.eyeHeight < 1e9)) throw Error(ErrorCode::InvalidArgument, "ground map: eye height " + numberText(p.eyeHeight) + " is not in (0, 1e9)");
    if (!(p.near >= 0.0 && p.near < 1e9)) throw Error(ErrorCode::InvalidArgument, "ground map: near " + numberText(p.near) + " is not in [0, 1e9)");
    if (!(p.far > p.near && p.far <= 1e9)) {
        throw Error(ErrorCode::InvalidArgument, "ground map: far " + numberText(p.far) + " must be > near (" + numberText(p.near) + ") and <= 1e9");
    }
    if (!(p.fovDegrees > 0.0 && p.fovDegrees < kMaxFov)) {
        throw Error(ErrorCode::InvalidArgument, "ground map: field of view " + numberText(p.fovDegrees) + " degrees is not in (0, 170)");
    }
    if (p.rows.empty()) return;
    if (p.rows.size() < 2 || p.rows.size() > std::size_t(map_rules::kMaxGroundRows))
        throw Error(ErrorCode::InvalidArgument, "ground map: a row profile of " + std::to_string(p.rows.size()) +
                                                    " values is outside [2, " + std::to_string(map_rules::kMaxGroundRows) + "]");
    if (p.rows.front() != 0.0 || p.rows.back() != 1.0)
        throw Error(ErrorCode::InvalidArgument, "ground map: the row profile must run from 0 to 1");
    for (std::size_t k = 1; k < p.rows.size(); ++k)
        if (!(p.rows[k] > p.rows[k - 1]))  // NaN fails too
            throw Error(ErrorCode::InvalidArgument, "ground map: the row profile is not strictly increasing at value " +
                                                        std::to_string(k));
}

glm::dvec2 groundDistort(const GroundParams& params, glm::dvec2 p) {
    const Geometry g(params);
    const double u = std::clamp(p.x, 0.0, 1.0), v = std::clamp(p.y, 0.0, 1.0);
    const double z = g.groundZ(v);
    // Rows: image row of the ground point in the pitched camera, or the profile's.
    double vd = 0.0;
    if (params.rows.empty()) {
        const double beta = std::atan2(g.h, z) - g.pitch;
        vd = 0.5 + 0.5 * std::tan(beta) / g.tanPhi;
    } else {
        vd = profileRow(params.rows, v);
    }
    // Columns: viewing angle over the angle of the field's edge at this depth.
    const double a = g.halfWidth / g.zCam(z);
    double ud = 0.5 + 0.5 * std::atan((2.0 * u - 1.0) * a) / std::atan(a);
    // Edges exactly onto edges (the formulas reach them only to rounding).
    if (v == 0.0 || v == 1.0) vd = v;
    if (u == 0.0 || u == 1.0 || u == 0.5) ud = u;
    return {std::clamp(ud, 0.0, 1.0), std::clamp(vd, 0.0, 1.0)};
}

glm::dvec2 groundUndistort(const GroundParams& params, glm::dvec2 pd) {
    const Geometry g(params);
    const double ud = std::clamp(pd.x, 0.0, 1.0), vd = std::clamp(pd.y, 0.0, 1.0);
    double v = 0.0, z = 0.0;
    if (params.rows.empty()) {
        const double alpha = g.pitch + std::atan((2.0 * vd - 1.0) * g.tanPhi);
        z = g.h * std::cos(alpha) / std::sin(alpha);
        v = 1.0 - (z - g.nearZ) / (g.farZ - g.nearZ);
    } else {
        v = profileInverse(params.rows, vd);
        z = g.groundZ(v);
    }
    const double a = g.halfWidth / g.zCam(z);
    double u = 0.5 + 0.5 * std::tan((2.0 * ud - 1.0) * std::atan(a)) / a;
    if (vd == 0.0 || vd == 1.0) v = vd;
    if (ud == 0.0 || ud == 1.0 || ud == 0.5) u = ud;
    return {std::clamp(u, 0.0, 1.0), std::clamp(v, 0.0, 1.0)};
}

SamplingMap buildGroundMap(const GroundParams& params, int columns, int rows) {
    checkGroundParams(params);
    if (columns < 2 || rows < 2 || columns > kMaxMapSide || rows > kMaxMapSide) {
        throw Error(ErrorCode::InvalidArgument, "ground map grid " + std::to_string(columns) + "x" + std::to_string(rows) +
                                                    " is outside [2, " + std::to_string(kMaxMapSide) + "] nodes per side");
    }
    std::vector<glm::vec2> nodes(std::size_t(columns) * rows);
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i) {
            const glm::dvec2 d = groundDistort(params, {double(i) / (columns - 1), double(j) / (rows - 1)});
            nodes[std::size_t(j) * columns + i] = glm::vec2(float(d.x), float(d.y));
        }
    // Every row of nodes is one horizontal line (v_d depends on v alone) and u_d grows along it,
    // so every cell is a trapezoid with horizontal parallel sides: convex, never folded.
    return SamplingMap(columns, rows, std::move(nodes));
}

format::AnalyticMap toAnalytic(const GroundParams& params) {
    checkGroundParams(params);
    format::AnalyticMap a;
    a.kind = enumName(format::MapKind::Ground);
    a.scalars = {{"eyeHeight", params.eyeHeight}, {"near", params.near}, {"far", params.far}, {"fovDegrees", params.fovDegrees}};
    a.groundRows.assign(params.rows.begin(), params.rows.end());
    return a;
}

GroundParams groundFromAnalytic(const format::AnalyticMap& analytic) {
    if (!analytic.is(format::MapKind::Ground)) {
        throw Error(ErrorCode::InvalidArgument, "analytic map of kind \"" + analytic.kind + "\" is not a ground map");
    }
    auto get = [&](const char* name) {
        const auto it = analytic.scalars.find(name);
        if (it == analytic.scalars.end()) {
            throw Error(ErrorCode::InvalidArgument, std::string("ground map: missing parameter \"") + name + "\"");
        }
        return it->second;
    };
    GroundParams p;
    p.eyeHeight = get("eyeHeight");
    p.near = get("near");
    p.far = get("far");
    p.fovDegrees = get("fovDegrees");
    p.rows.assign(analytic.groundRows.begin(), analytic.groundRows.end());
    checkGroundParams(p);
    return p;
}

}  // namespace conus::codec
