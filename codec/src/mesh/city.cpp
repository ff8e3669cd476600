// The procedural city (city.h). Random numbers come from std::mt19937_64, whose output the C++
// standard fixes, mapped to [0,1) by hand (the standard's distributions differ between library
// implementations), so a seed gives the same city everywhere.
#include "conus/codec/mesh/city.h"

#include <cmath>
#include <random>
#include <string>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

constexpr double kPi = 3.14159265358979323846;

class Random {
public:
    explicit Random(std::uint64_t seed) : m_engine(seed) {}
    double uniform() { return double(m_engine() >> 11) * 0x1.0p-53; }  // [0, 1)
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    int integer(int lo, int hi) { return std::min(hi, lo + int(uniform() * (hi - lo + 1))); }  // [lo, hi]

private:
    std::mt19937_64 m_engine;
};

// A box with flat faces (four vertices each, so normals are per face): centre, half sizes along
// its own axes, turned about y so that its x axis points along `heading` (x, z).
void addBox(Mesh& mesh, glm::dvec3 centre, glm::dvec3 half, glm::dvec2 heading, glm::vec3 colour) {
    const glm::dvec3 ax(heading.x, 0, heading.y), ay(0, 1, 0), az = glm::cross(ax, ay);
    // Each face: its outward axis and two in-plane axes ordered so (s x t) points outward.
    const glm::dvec3 axes[3] = {ax * half.x, ay * half.y, az * half.z};
    for (int axis = 0; axis < 3; ++axis)
        for (int sign = -1; sign <= 1; sign += 2) {
            const glm::dvec3 n = axes[axis] * double(sign);
            glm::dvec3 s = axes[(axis + 1) % 3], t = axes[(axis + 2) % 3];
            if (sign < 0) std::swap(s, t);
            const glm::vec3 normal(glm::normalize(n));
            const std::uint32_t base = std::uint32_t(mesh.positions.size());
            for (const glm::dvec2 c : {glm::dvec2(-1, -1), glm::dvec2(1, -1), glm::dvec2(1, 1), glm::dvec2(-1, 1)}) {
                mesh.positions.emplace_back(centre + n + s * c.x + t * c.y);
                mesh.normals.push_back(normal);
                mesh.colours.push_back(colour);
            }
            mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        }
}

}  // namespace

CityScene::CityScene(const CityOptions& options) : m_options(options) {
    auto bad = [](const std::string& why) { throw Error(ErrorCode::InvalidArgument, "city: " + why); };
    if (options.blocksX < 1 || options.blocksX > 64 || options.blocksZ < 1 || options.blocksZ > 64)
        bad("blocks must be 1 to 64 a side");
    if (options.cars < 0 || options.cars > 256) bad("cars must be 0 to 256");
    if (!(options.blockSize >= 10 && options.blockSize <= 1000)) bad("block size must be 10 to 1000 metres");
    if (!(options.streetWidth >= 8 && options.streetWidth <= 100)) bad("street width must be 8 to 100 metres");
    if (!(std::abs(options.carSpeed) <= 100)) bad("car speed must be at most 100 metres a second");

    const double B = options.blockSize, S = options.streetWidth;
    m_halfX = (options.blocksX * B + (options.blocksX + 1) * S) / 2;
    m_halfZ = (options.blocksZ * B + (options.blocksZ + 1) * S) / 2;
    auto blockMin = [&](int i, int j) { return glm::dvec2(-m_halfX + S + i * (B + S), -m_halfZ + S + j * (B + S)); };
    Random random(options.seed);

    // The ground: asphalt, a quad under the whole city.
    {
        const std::uint32_t base = 0;
        const glm::vec3 up(0, 1, 0), asphalt(0.12f, 0.12f, 0.13f);
        for (const glm::dvec2 c : {glm::dvec2(-1, -1), glm::dvec2(-1, 1), glm::dvec2(1, 1), glm::dvec2(1, -1)}) {
            m_static.positions.emplace_back(c.x * m_halfX, 0.0, c.y * m_halfZ);
            m_static.normals.push_back(up);
            m_static.colours.push_back(asphalt);
        }
        m_static.indices = {base, base + 1, base + 2, base, base + 2, base + 3};
    }
    // Blocks: a pavement slab, then 1..3 x 1..3 lots, each a building of its own height and colour.
    const glm::vec3 palette[] = {{0.70f, 0.62f, 0.50f}, {0.55f, 0.58f, 0.65f}, {0.75f, 0.45f, 0.35f},
                                 {0.80f, 0.78f, 0.70f}, {0.40f, 0.50f, 0.45f}, {0.60f, 0.35f, 0.45f}};
    for (int j = 0; j < options.blocksZ; ++j)
        for (int i = 0; i < options.blocksX; ++i) {
            const glm::dvec2 lo = blockMin(i, j);
            addBox(m_static, {lo.x + B / 2, 0.1, lo.y + B / 2}, {B / 2, 0.1, B / 2}, {1, 0}, {0.45f, 0.45f, 0.43f});
            const int lotsX = random.integer(1, 3), lotsZ = random.integer(1, 3);
            const double margin = 2.0, lotX = (B - margin) / lotsX, lotZ = (B - margin) / lotsZ;
            for (int b = 0; b < lotsZ; ++b)
                for (int a = 0; a < lotsX; ++a) {
                    const double height = random.uniform(6, 20) * (random.uniform() < 0.15 ? 3.0 : 1.0);
                    const glm::vec3 tint = palette[random.integer(0, 5)] * float(random.uniform(0.85, 1.1));
                    const double hx = (lotX - margin) / 2, hz = (lotZ - margin) / 2;
                    const glm::dvec3 centre(lo.x + margin + lotX * (a + 0.5) - margin / 2, 0.2 + height / 2,
                                            lo.y + margin + lotZ * (b + 0.5) - margin / 2);
                    addBox(m_static, centre, {hx, height / 2, hz}, {1, 0}, tint);
                    m_maxHeight = std::max(m_maxHeight, 0.2 + height);
                }
        }
    // Cars: each drives a loop around a rectangle of 1..2 x 1..2 blocks; the two directions keep
    // to opposite lanes of the street, a quarter street either side of its centre line.
    const glm::vec3 carColours[] = {{0.85f, 0.08f, 0.06f}, {0.95f, 0.80f, 0.05f}, {0.05f, 0.25f, 0.85f},
                                    {0.05f, 0.70f, 0.20f}, {0.95f, 0.95f, 0.95f}, {0.90f, 0.40f, 0.05f}};
    for (int c = 0; c < options.cars; ++c) {
        Car car;
        const int i0 = random.integer(0, options.blocksX - 1), j0 = random.integer(0, options.blocksZ - 1);
        const int i1 = std::min(options.blocksX - 1, i0 + random.integer(0, 1));
        const int j1 = std::min(options.blocksZ - 1, j0 + random.integer(0, 1));
        const bool clockwise = random.uniform() < 0.5;
        const double lane = clockwise ? -S / 4 : S / 4;  // inner or outer lane
        car.loopMin = blockMin(i0, j0) - glm::dvec2(S / 2 + lane);
        car.loopMax = blockMin(i1, j1) + glm::dvec2(B + S / 2 + lane);
        car.radius = S / 4;
        const double perimeter = 2 * (car.loopMax.x - car.loopMin.x + car.loopMax.y - car.loopMin.y) - (8 - 2 * kPi) * car.radius;
        car.phase = random.uniform() * perimeter;
        car.speed = options.carSpeed * random.uniform(0.7, 1.3) * (clockwise ? -1 : 1);
        car.colour = carColours[random.integer(0, 5)];
        car.size = {4.4, 1.5, 1.9};
        m_cars.push_back(car);
    }
}

void CityScene::loopAt(const Car& car, double s, glm::dvec2& position, glm::dvec2& heading) const {
    const double r = car.radius;
    const glm::dvec2 lo = car.loopMin, hi = car.loopMax;
    const double lx = hi.x - lo.x - 2 * r, lz = hi.y - lo.y - 2 * r, arc = kPi * r / 2;
    const double perimeter = 2 * (lx + lz) + 4 * arc;
    s = std::fmod(s, perimeter);
    if (s < 0) s += perimeter;
    // Four straight edges, each followed by a quarter circle, driven counter-clockwise in (x, z):
    // +x along z = lo, +z along x = hi, -x along z = hi, -z along x = lo.
    const double lengths[4] = {lx, lz, lx, lz};
    const glm::dvec2 starts[4] = {{lo.x + r, lo.y}, {hi.x, lo.y + r}, {hi.x - r, hi.y}, {lo.x, hi.y - r}};
    const glm::dvec2 directions[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    for (int k = 0; k < 4; ++k) {
        if (s <= lengths[k]) {
            position = starts[k] + directions[k] * s;
            heading = directions[k];
            return;
        }
        s -= lengths[k];
        if (s <= arc || k == 3) {
            // The arc's centre is r to the left of the straight's end (left of d is (-d.y, d.x)).
            const glm::dvec2 d = directions[k], left(-d.y, d.x);
            const glm::dvec2 centre = starts[k] + d * lengths[k] + left * r;
            const double angle = std::min(s, arc) / r;  // turned so far
            position = centre - left * (r * std::cos(angle)) + d * (r * std::sin(angle));
            heading = d * std::cos(angle) + left * std::sin(angle);
            return;
        }
        s -= arc;
    }
}

const CityScene::Car& CityScene::car(int index) const {
    if (index < 0 || index >= carCount())
        throw Error(ErrorCode::InvalidArgument, "city: no car " + std::to_string(index) + " (it has " + std::to_string(carCount()) + ")");
    return m_cars[std::size_t(index)];
}

glm::dvec3 CityScene::carCentre(int index, double t) const {
    const Car& c = car(index);
    glm::dvec2 position, heading;
    loopAt(c, c.phase + c.speed * t, position, heading);
    return {position.x, c.size.y / 2 + 0.3, position.y};
}

glm::dvec3 CityScene::carHeading(int index, double t) const {
    const Car& c = car(index);
    glm::dvec2 position, heading;
    loopAt(c, c.phase + c.speed * t, position, heading);
    if (c.speed < 0) heading = -heading;  // the loop runs counter-clockwise; this car drives it backwards
    return {heading.x, 0, heading.y};
}

Mesh CityScene::meshAt(double t) const {
    if (!std::isfinite(t)) throw Error(ErrorCode::InvalidArgument, "city: time must be finite");
    Mesh mesh = m_static;
    for (int c = 0; c < carCount(); ++c) {
        const glm::dvec3 heading = carHeading(c, t);
        addBox(mesh, carCentre(c, t), car(c).size / 2.0, {heading.x, heading.z}, car(c).colour);
    }
    return mesh;
}

}  // namespace conus::codec
