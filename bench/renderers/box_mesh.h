// Meshes the reflection benches build their scenes from: axis boxes of four-corner faces (so that
// flat faces shade flat) and quads, each corner its own colour.
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "conus/core/mesh.h"

namespace conus::bench {

// A quad of four corners, each its own colour.
inline void addQuad(Mesh& m, const std::array<glm::vec3, 4>& corners, const std::array<glm::vec3, 4>& colours) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (int k = 0; k < 4; ++k) {
        m.positions.push_back(corners[k]);
        m.colours.push_back(colours[k]);
    }
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

// An axis box of its own four-corner faces, coloured by `colour` at each corner.
template <class Colour>
void addBox(Mesh& m, glm::vec3 lo, glm::vec3 hi, Colour colour) {
    const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : faces) {
        std::array<glm::vec3, 4> corners, colours;
        for (int k = 0; k < 4; ++k) {
            const int c = f[k];
            corners[k] = glm::vec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
            colours[k] = colour(corners[k]);
        }
        addQuad(m, corners, colours);
    }
}

// A colour ramp across the box [lo, hi] (red along x, green along y, blue along z), so that a
// misplaced hit shows.
inline auto rampAcross(glm::vec3 lo, glm::vec3 hi) {
    return [lo, hi](glm::vec3 p) {
        return glm::vec3((p.x - lo.x) / (hi.x - lo.x), 0.25f + 0.5f * (p.y - lo.y) / (hi.y - lo.y), (p.z - lo.z) / (hi.z - lo.z));
    };
}

}  // namespace conus::bench
