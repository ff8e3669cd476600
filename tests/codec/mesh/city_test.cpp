// The procedural city: the same seed gives the same city, cars move continuously and stay on the
// streets, every mesh is well formed.
#include "conus/codec/mesh/city.h"

#include <gtest/gtest.h>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

void expectValidMesh(const Mesh& mesh) {
    EXPECT_NO_THROW(checkMesh(mesh, "city"));
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    ASSERT_EQ(mesh.colours.size(), mesh.positions.size());
    for (const glm::vec3& n : mesh.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);
    // Flat faces: each triangle's winding agrees with its vertex normals (outward).
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
        const glm::vec3 p0 = mesh.positions[mesh.indices[t]], p1 = mesh.positions[mesh.indices[t + 1]],
                        p2 = mesh.positions[mesh.indices[t + 2]];
        const glm::vec3 face = glm::normalize(glm::cross(p1 - p0, p2 - p0));
        ASSERT_GT(glm::dot(face, mesh.normals[mesh.indices[t]]), 0.999f) << "triangle " << t / 3;
    }
}

TEST(City, DeterministicFromTheSeed) {
    CityOptions options;
    options.seed = 42;
    const CityScene a(options), b(options);
    const Mesh ma = a.meshAt(3.7), mb = b.meshAt(3.7);
    EXPECT_EQ(ma.positions, mb.positions);
    EXPECT_EQ(ma.colours, mb.colours);
    EXPECT_EQ(ma.indices, mb.indices);
    options.seed = 43;
    const CityScene c(options);
    EXPECT_NE(c.meshAt(3.7).positions, ma.positions);
}

TEST(City, MeshesAreValid) {
    CityOptions options;
    options.blocksX = 5;
    options.blocksZ = 3;
    options.cars = 9;
    const CityScene city(options);
    for (double t : {0.0, 1.25, 17.0, 300.5}) {
        SCOPED_TRACE(t);
        const Mesh mesh = city.meshAt(t);
        expectValidMesh(mesh);
        // Ground (2) + a slab per block, its buildings, and one box (12 triangles) per car.
        EXPECT_EQ(mesh.triangleCount(), city.staticMesh().triangleCount() + 12u * 9);
        for (const glm::vec3& p : mesh.positions) {
            EXPECT_LE(std::abs(p.x), city.halfExtentX() + 1e-3);
            EXPECT_LE(std::abs(p.z), city.halfExtentZ() + 1e-3);
            EXPECT_GE(p.y, -1e-6f);
            EXPECT_LE(p.y, city.maxHeight() + 1e-3);
        }
    }
    // Buildings of varied heights.
    EXPECT_GT(city.maxHeight(), 15);
}

TEST(City, CarsMoveContinuouslyAlongTheStreets) {
    CityOptions options;
    options.cars = 8;
    options.carSpeed = 12;
    const CityScene city(options);
    const double dt = 0.01, maxSpeed = 1.3 * options.carSpeed;
    const double B = options.blockSize, S = options.streetWidth;
    for (int car = 0; car < city.carCount(); ++car) {
        SCOPED_TRACE(car);
        glm::dvec3 previous = city.carCentre(car, 0), previousHeading = city.carHeading(car, 0);
        double travelled = 0, largestStep = 0;
        for (double t = dt; t <= 40; t += dt) {
            const glm::dvec3 c = city.carCentre(car, t), h = city.carHeading(car, t);
            const double step = glm::length(c - previous);
            largestStep = std::max(largestStep, step);
            travelled += step;
            // The heading turns at most speed / corner radius (S / 4) radians a second.
            EXPECT_LE(glm::length(h - previousHeading), maxSpeed / (S / 4) * dt * 1.01);
            EXPECT_NEAR(glm::length(h), 1.0, 1e-9);
            // It moves the way it faces.
            if (step > 0) {
                EXPECT_GT(glm::dot(c - previous, h), 0.9 * step);
            }
            // On a street: never inside a block.
            const double fx = std::fmod(c.x + city.halfExtentX(), B + S), fz = std::fmod(c.z + city.halfExtentZ(), B + S);
            EXPECT_FALSE(fx > S && fz > S) << "inside a block at t = " << t;
            previous = c;
            previousHeading = h;
        }
        EXPECT_LE(largestStep, maxSpeed * dt * (1 + 1e-9));
        EXPECT_GT(travelled, 0.7 * options.carSpeed * 40 * 0.99);
    }
    // Whole vertices too: a car box's corners move at most (speed + turn rate * half diagonal) dt.
    const Mesh a = city.meshAt(5.0), b = city.meshAt(5.0 + dt);
    const std::size_t first = city.staticMesh().positions.size();
    double largest = 0;
    for (std::size_t i = 0; i < first; ++i) ASSERT_EQ(a.positions[i], b.positions[i]);
    for (std::size_t i = first; i < a.positions.size(); ++i)
        largest = std::max(largest, double(glm::length(a.positions[i] - b.positions[i])));
    EXPECT_GT(largest, 0);
    EXPECT_LE(largest, (maxSpeed + maxSpeed / (S / 4) * 2.5) * dt);
}

TEST(City, BadOptions) {
    auto with = [](auto edit) {
        CityOptions o;
        edit(o);
        return o;
    };
    EXPECT_THROW(CityScene(with([](CityOptions& o) { o.blocksX = 0; })), Error);
    EXPECT_THROW(CityScene(with([](CityOptions& o) { o.blocksZ = 65; })), Error);
    EXPECT_THROW(CityScene(with([](CityOptions& o) { o.cars = -1; })), Error);
    EXPECT_THROW(CityScene(with([](CityOptions& o) { o.streetWidth = 2; })), Error);
    EXPECT_THROW(CityScene(with([](CityOptions& o) { o.blockSize = std::nan(""); })), Error);
    const CityScene city;
    EXPECT_THROW(city.carCentre(city.carCount(), 0), Error);
    EXPECT_THROW(city.carCentre(-1, 0), Error);
    EXPECT_THROW(city.meshAt(std::nan("")), Error);
}

}  // namespace
}  // namespace conus::codec
