// The procedural city of the paper's focus-plus-context sequences (section 6, Figure 7): a ground
// plane with a grid of blocks, each holding buildings (boxes of varied height and colour), and
// cars (boxes) driving loops along the streets around blocks. Everything follows from the seed:
// the same options give the same city, and the cars' positions are continuous functions of time
// (each loop is a rounded rectangle driven at constant speed, so position and heading never jump).
// World frame: y up, the ground at y = 0, the city centred on the origin, lengths in metres.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "conus/core/mesh.h"

namespace conus::codec {

struct CityOptions {
    std::uint64_t seed = 1;
    int blocksX = 4, blocksZ = 4;  // blocks along x and z, 1..64 each
    int cars = 6;                  // 0..256
    double blockSize = 40;         // side of a block, metres
    double streetWidth = 12;       // between blocks (and around the city)
    double carSpeed = 10;          // metres a second
};

class CityScene {
public:
    // Throws conus::Error(InvalidArgument) for options outside their ranges.
    explicit CityScene(const CityOptions& options = {});

    // The whole scene at time t (seconds): ground, buildings, then the cars, colours per vertex,
    // normals per vertex (flat faces).
    Mesh meshAt(double t) const;
    // Ground and buildings only (what does not move).
    const Mesh& staticMesh() const { return m_static; }

    int carCount() const { return static_cast<int>(m_cars.size()); }
    // The centre of car `car`'s box at time t (throws InvalidArgument for a car out of range).
    glm::dvec3 carCentre(int car, double t) const;
    // Unit driving direction of car `car` at time t (horizontal).
    glm::dvec3 carHeading(int car, double t) const;

    // The city's extent: x and z in [-halfExtent, halfExtent], y in [0, maxHeight].
    double halfExtentX() const { return m_halfX; }
    double halfExtentZ() const { return m_halfZ; }
    double maxHeight() const { return m_maxHeight; }
    const CityOptions& options() const { return m_options; }

private:
    struct Car {
        glm::dvec2 loopMin, loopMax;  // the loop's straight-line rectangle in (x, z)
        double radius;                // corner radius
        double phase;                 // metres along the loop at t = 0
        double speed;                 // metres a second, sign = direction
        glm::vec3 colour;
        glm::dvec3 size;              // length (along heading), height, width
    };
    const Car& car(int index) const;  // throws InvalidArgument out of range
    // Position (x, z) and unit heading on a car's loop at arc length s.
    void loopAt(const Car& car, double s, glm::dvec2& position, glm::dvec2& heading) const;

    CityOptions m_options;
    Mesh m_static;
    std::vector<Car> m_cars;
    double m_halfX = 0, m_halfZ = 0, m_maxHeight = 0;
};

}  // namespace conus::codec
