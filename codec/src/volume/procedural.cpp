#include "conus/codec/volume/procedural.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "conus/core/error.h"
#include "conus/core/limits.h"

namespace conus::codec {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kBlurVoxels = 1.0;  // the Shepp-Logan phantom's point spread, in voxels

Volume grid(int n, const char* what) {
    if (n < 2 || n > 1024 || std::int64_t{n} * n * n > kMaxVolumeVoxels)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": size " + std::to_string(n) +
                                                    " is outside [2, 1024] or its n^3 samples pass the limit of " +
                                                    std::to_string(kMaxVolumeVoxels));
    Volume v;
    v.width = v.height = v.depth = n;
    v.spacing = glm::dvec3(2.0 / (n - 1));
    v.values.resize(static_cast<std::size_t>(n) * n * n);
    return v;
}

// Position of sample i of n in [-1, 1].
double coordinate(int i, int n) { return -1.0 + 2.0 * i / (n - 1); }

}  // namespace

Volume marschnerLobb(int n) {
    Volume v = grid(n, "marschner-lobb");
    // The paper's parameters: f_M = 6, alpha = 0.25.
    constexpr double kFm = 6.0, kAlpha = 0.25;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double px = coordinate(x, n), py = coordinate(y, n), pz = coordinate(z, n);
                const double r = std::sqrt(px * px + py * py);
                const double rho = std::cos(2.0 * kPi * kFm * std::cos(kPi * r / 2.0));
                v.values[v.index(x, y, z)] =
                    static_cast<float>((1.0 - std::sin(kPi * pz / 2.0) + kAlpha * (1.0 + rho)) / (2.0 * (1.0 + kAlpha)));
            }
    return v;
}

Volume sheppLogan3d(int n) {
    Volume v = grid(n, "shepp-logan");
    // The modified 3-D Shepp-Logan phantom: additive value; semi-axes a, b, c; centre; Euler angles
    // phi, theta, psi in degrees (z-x-z). Contrast raised from Shepp-Logan's original to see the
    // inner ellipsoids (Toft's modification).
    struct Ellipsoid {
        double value, a, b, c, x, y, z, phi, theta, psi;
    };
    static const Ellipsoid kEllipsoids[] = {
        {1.0, 0.69, 0.92, 0.81, 0, 0, 0, 0, 0, 0},
        {-0.8, 0.6624, 0.874, 0.78, 0, -0.0184, 0, 0, 0, 0},
        {-0.2, 0.11, 0.31, 0.22, 0.22, 0, 0, -18, 0, 10},
        {-0.2, 0.16, 0.41, 0.28, -0.22, 0, 0, 18, 0, 10},
        {0.1, 0.21, 0.25, 0.41, 0, 0.35, -0.15, 0, 0, 0},
        {0.1, 0.046, 0.046, 0.05, 0, 0.1, 0.25, 0, 0, 0},
        {0.1, 0.046, 0.046, 0.05, 0, -0.1, 0.25, 0, 0, 0},
        {0.1, 0.046, 0.023, 0.05, -0.08, -0.605, 0, 0, 0, 0},
        {0.1, 0.023, 0.023, 0.02, 0, -0.606, 0, 0, 0, 0},
        {0.1, 0.023, 0.046, 0.02, 0.06, -0.605, 0, 0, 0, 0},
    };
    struct Placed {
        const Ellipsoid* e;
        glm::dmat3 rotation;  // world -> ellipsoid axes
    };
    std::vector<Placed> placed;
    for (const Ellipsoid& e : kEllipsoids) {
        const double p = e.phi * kPi / 180, t = e.theta * kPi / 180, s = e.psi * kPi / 180;
        const glm::dmat3 rz1(std::cos(p), std::sin(p), 0, -std::sin(p), std::cos(p), 0, 0, 0, 1);
        const glm::dmat3 rx(1, 0, 0, 0, std::cos(t), std::sin(t), 0, -std::sin(t), std::cos(t));
        const glm::dmat3 rz2(std::cos(s), std::sin(s), 0, -std::sin(s), std::cos(s), 0, 0, 0, 1);
        placed.push_back({&e, glm::transpose(rz2 * rx * rz1)});
    }
    // Each voxel holds the phantom seen through a Gaussian point spread of kBlurVoxels standard
    // deviation (what a scanner measures), not its value at the centre nor its mean over the
    // voxel's cube: the skull is a shell about one voxel thick at n = 64, and even a box mean of a
    // shell that thin depends on where the shell crosses the voxel grid (the peak a ray meets near
    // the x axis ran from 0.49 to 0.77 from one ray to the next), which a ray caster draws as rings
    // over the whole head. Blurred past the grid's Nyquist limit, the samples no longer follow the
    // shell's phase (0.39 to 0.42 there). Each ellipsoid adds Phi(-d / sigma) of its value, d the
    // signed distance to its surface to first order ((s - 1) / |grad s|, s the normalized radius;
    // exact for a sphere): the blurred indicator of a surface flat over the blur's width.
    const double sigma = kBlurVoxels * v.spacing.x;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const glm::dvec3 p(coordinate(x, n), coordinate(y, n), coordinate(z, n));
                double value = 0;
                for (const Placed& e : placed) {
                    const glm::dvec3 axes(e.e->a, e.e->b, e.e->c);
                    const glm::dvec3 r = (e.rotation * (p - glm::dvec3(e.e->x, e.e->y, e.e->z))) / axes;
                    const double s = glm::length(r), gradient = s > 0.0 ? glm::length(r / axes) / s : 0.0;
                    const double d = gradient > 0.0 ? (s - 1.0) / gradient : -std::min({axes.x, axes.y, axes.z});
                    value += e.e->value * 0.5 * std::erfc(d / (sigma * std::sqrt(2.0)));
                }
                v.values[v.index(x, y, z)] = static_cast<float>(std::clamp(value, 0.0, 1.0));
            }
    return v;
}

Volume proceduralVolume(const std::string& spec) {
    const auto bad = [&] {
        return Error(ErrorCode::InvalidArgument, "volume '" + spec +
                                                     "': expected procedural:marschner-lobb[:n] or procedural:shepp-logan[:n]");
    };
    if (spec.rfind("procedural:", 0) != 0) throw bad();
    std::string name = spec.substr(11);
    int n = 64;
    if (const std::size_t colon = name.find(':'); colon != std::string::npos) {
        const std::string size = name.substr(colon + 1);
        if (size.empty() || size.size() > 5 || size.find_first_not_of("0123456789") != std::string::npos) throw bad();
        n = std::stoi(size);
        name.resize(colon);
    }
    if (name == "marschner-lobb") return marschnerLobb(n);
    if (name == "shepp-logan") return sheppLogan3d(n);
    throw bad();
}

}  // namespace conus::codec
