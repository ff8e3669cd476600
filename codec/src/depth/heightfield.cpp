// CoNUS height fields: procedural terrain, encode through the ground map, undistort to a mesh.
#include "conus/codec/depth/heightfield.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <regex>
#include <string>

#include "conus/codec/image/encode.h"
#include "conus/core/display.h"
#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/core/parallel.h"

namespace conus::codec {
namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- Gradient noise ----

std::uint32_t hash(std::int32_t x, std::int32_t y, std::uint32_t seed) {
    std::uint32_t h = seed * 0x9E3779B9u ^ static_cast<std::uint32_t>(x) * 0x85EBCA6Bu ^
                      static_cast<std::uint32_t>(y) * 0xC2B2AE35u;
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return h;
}

double gradientDot(std::int32_t ix, std::int32_t iy, std::uint32_t seed, double dx, double dy) {
    const double angle = hash(ix, iy, seed) * (2.0 * kPi / 4294967296.0);
    return std::cos(angle) * dx + std::sin(angle) * dy;
}

// Perlin-style gradient noise in about [-0.7, 0.7], quintic fade so slopes are continuous.
double gradientNoise(double x, double y, std::uint32_t seed) {
    const double fx = std::floor(x), fy = std::floor(y);
    const auto ix = static_cast<std::int32_t>(fx), iy = static_cast<std::int32_t>(fy);
    const double dx = x - fx, dy = y - fy;
    const auto fade = [](double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); };
    const double sx = fade(dx), sy = fade(dy);
    const double n00 = gradientDot(ix, iy, seed, dx, dy), n10 = gradientDot(ix + 1, iy, seed, dx - 1, dy);
    const double n01 = gradientDot(ix, iy + 1, seed, dx, dy - 1), n11 = gradientDot(ix + 1, iy + 1, seed, dx - 1, dy - 1);
    const double a = n00 + sx * (n10 - n00), b = n01 + sx * (n11 - n01);
    return a + sy * (b - a);
}

// In about [0, 1]: a blend of fBm (rolling) and ridged multifractal (sharp crests) noise.
double terrainValue(double u, double v, const TerrainOptions& o) {
    double fbm = 0, ridged = 0, amplitude = 1, total = 0, frequency = o.features, weight = 1;
    for (int k = 0; k < o.octaves; ++k) {
        // A per-octave seed and offset so octaves do not line up at the lattice origin.
        const std::uint32_t seed = o.seed * 131u + static_cast<std::uint32_t>(k);
        const double x = u * frequency + 17.31 * k, y = v * frequency - 9.77 * k;
        const double n = gradientNoise(x, y, seed);
        fbm += amplitude * n;
        double r = 1.0 - std::abs(n) * 1.4;
        r = std::clamp(r, 0.0, 1.0);
        r *= r * weight;
        weight = std::clamp(r * 1.6, 0.0, 1.0);  // crests carry detail, valleys stay smooth
        ridged += amplitude * r;
        total += amplitude;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    const double hills = std::clamp(0.5 + fbm / total, 0.0, 1.0);
    const double mountains = std::clamp(ridged / total * 1.3, 0.0, 1.0);
    const double value = (1.0 - o.ridges) * hills + o.ridges * mountains * (0.4 + 0.8 * hills);
    return std::pow(std::clamp(value, 0.0, 1.0), 1.3);  // flatter valleys, steeper peaks
}

// ---- Checks and helpers ----

void checkSize(int w, int h, const char* what) {
    if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": size " + std::to_string(w) + "x" +
                                                    std::to_string(h) + " is outside [1, 65536] per side");
}

int heightChannel(const Image& heights, const char* what) {
    checkImage(heights, what);
    const int z = heights.channelIndex("Z");
    if (z >= 0) return z;
    if (heights.channelCount() == 1) return 0;
    throw Error(ErrorCode::InvalidArgument, std::string(what) + ": the DEM has " +
                                                std::to_string(heights.channelCount()) +
                                                " channels and none named Z");
}

// R,G,B,Z at the DEM's size: the one source image the encoder filters.
Image combine(const Image& heights, const Image& colour, const char* what) {
    const int z = heightChannel(heights, what);
    checkImage(colour, what);
    if (colour.width != heights.width || colour.height != heights.height)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": colour " + std::to_string(colour.width) + "x" +
                                                    std::to_string(colour.height) + " differs from the DEM's " +
                                                    std::to_string(heights.width) + "x" +
                                                    std::to_string(heights.height));
    int rgb[3];
    for (int c = 0; c < 3; ++c) {
        rgb[c] = colour.channelIndex(std::string(1, "RGB"[c]));
        if (rgb[c] < 0) rgb[c] = std::min(c, colour.channelCount() - 1);  // grey or unnamed channels
    }
    Image out = makeImage(heights.width, heights.height, {"R", "G", "B", "Z"});
    const std::size_t n = static_cast<std::size_t>(heights.width) * heights.height;
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) out.pixels[i * 4 + c] = colour.pixels[i * colour.channels.size() + rgb[c]];
        const float h = heights.pixels[i * heights.channels.size() + z];
        if (!std::isfinite(h))
            throw Error(ErrorCode::InvalidArgument, std::string(what) + ": DEM height at pixel " +
                                                        std::to_string(i % heights.width) + "," +
                                                        std::to_string(i / heights.width) + " is not finite");
        out.pixels[i * 4 + 3] = h;
    }
    return out;
}

format::DepthInfo heightDepth(const Image& rgbz, const std::string& units) {
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    const int z = rgbz.channelIndex("Z");
    for (std::size_t i = z; i < rgbz.pixels.size(); i += rgbz.channels.size()) {
        lo = std::min(lo, rgbz.pixels[i]);
        hi = std::max(hi, rgbz.pixels[i]);
    }
    format::DepthInfo d;
    d.kind = format::DepthKind::Height;
    d.units = units;
    d.near = lo;
    d.far = hi > lo ? hi : lo + 1.0f;  // the spec wants near < far, even for a flat field
    return d;
}

// Same geometry as ground_map.cpp's: the pitched camera's depth of the far edge sets the width.
double halfWidth(double eyeHeight, double near, double far, double fovDegrees) {
    const double alphaNear = std::atan2(eyeHeight, near), alphaFar = std::atan2(eyeHeight, far);
    const double pitch = 0.5 * (alphaNear + alphaFar);
    return (far * std::cos(pitch) + eyeHeight * std::sin(pitch)) * std::tan(0.5 * fovDegrees * kPi / 180.0);
}

void addNormals(Mesh& mesh) {
    mesh.normals.assign(mesh.positions.size(), glm::vec3(0.0f));
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        // Not normalized: the cross product's length weights each face by its area.
        const glm::vec3 n = glm::cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
        mesh.normals[a] += n;
        mesh.normals[b] += n;
        mesh.normals[c] += n;
    }
    for (glm::vec3& n : mesh.normals) {
        const float length = glm::length(n);
        n = length > 0.0f ? n / length : glm::vec3(0, 1, 0);
    }
}

}  // namespace

std::optional<TerrainOptions> proceduralTerrain(const std::string& source) {
    std::smatch m;
    if (!std::regex_match(source, m, std::regex("procedural(?::(\\d+))?(?::(\\d+))?"))) return std::nullopt;
    TerrainOptions options;
    if (m[1].matched) options.width = options.height = std::stoi(m[1].str().substr(0, 6));
    if (std::int64_t{options.width} * options.height > kMaxDemSamples)
        throw Error(ErrorCode::InvalidArgument, "procedural terrain " + std::to_string(options.width) + "x" +
                                                    std::to_string(options.height) + " holds more than the limit of " +
                                                    std::to_string(kMaxDemSamples) + " height samples");
    if (m[2].matched) options.seed = static_cast<std::uint32_t>(std::stoul(m[2].str().substr(0, 9)));
    return options;
}

Image generateTerrain(const TerrainOptions& o) {
    checkSize(o.width, o.height, "generateTerrain");
    if (!(o.reliefMetres >= 0.0 && o.reliefMetres < 1e6) || !(o.features > 0.0 && o.features < 1e4) ||
        o.octaves < 1 || o.octaves > 24 || !(o.ridges >= 0.0 && o.ridges <= 1.0))
        throw Error(ErrorCode::InvalidArgument,
                    "generateTerrain: relief " + std::to_string(o.reliefMetres) + ", features " +
                        std::to_string(o.features) + ", octaves " + std::to_string(o.octaves) + ", ridges " +
                        std::to_string(o.ridges) + ": want relief in [0,1e6), features in (0,1e4), octaves in "
                        "[1,24], ridges in [0,1]");
    Image out = makeImage(o.width, o.height, {"Z"});
    parallelRows(o.height, 0, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < o.width; ++x)
                out.at(x, y) = static_cast<float>(
                    o.reliefMetres * terrainValue((x + 0.5) / o.width, (y + 0.5) / o.height, o));
    });
    return out;
}

Image terrainColours(const Image& heights, glm::dvec2 extent) {
    const int z = heightChannel(heights, "terrainColours");
    if (!(extent.x > 0 && extent.y > 0))
        throw Error(ErrorCode::InvalidArgument, "terrainColours: field extent " + std::to_string(extent.x) + " x " +
                                                    std::to_string(extent.y) + " is not positive");
    const int w = heights.width, h = heights.height;
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            lo = std::min(lo, heights.at(x, y, z));
            hi = std::max(hi, heights.at(x, y, z));
        }
    const double range = hi > lo ? hi - lo : 1.0;
    const double cellX = extent.x / w, cellY = extent.y / h;
    // Height ramp stops (fraction of the range -> colour), linear RGB.
    struct Stop {
        double at;
        glm::dvec3 colour;
    };
    static constexpr Stop kRamp[] = {{0.00, {0.20, 0.36, 0.16}}, {0.30, {0.33, 0.48, 0.20}},
                                     {0.55, {0.55, 0.47, 0.30}}, {0.78, {0.50, 0.46, 0.43}},
                                     {0.90, {0.93, 0.94, 0.97}}, {1.00, {1.00, 1.00, 1.00}}};
    const glm::dvec3 rock(0.42, 0.40, 0.38);
    Image out = makeImage(w, h, {"R", "G", "B"});
    parallelRows(h, 0, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                const auto at = [&](int xx, int yy) {
                    return double(heights.at(std::clamp(xx, 0, w - 1), std::clamp(yy, 0, h - 1), z));
                };
                const double gx = (at(x + 1, y) - at(x - 1, y)) / (2.0 * cellX);
                const double gy = (at(x, y + 1) - at(x, y - 1)) / (2.0 * cellY);
                const double slope = std::sqrt(gx * gx + gy * gy);  // rise over run
                const double t = (at(x, y) - lo) / range;
                glm::dvec3 c = kRamp[0].colour;
                for (std::size_t k = 1; k < std::size(kRamp); ++k)
                    if (t <= kRamp[k].at) {
                        const double s = (t - kRamp[k - 1].at) / (kRamp[k].at - kRamp[k - 1].at);
                        c = glm::mix(kRamp[k - 1].colour, kRamp[k].colour, std::clamp(s, 0.0, 1.0));
                        break;
                    }
                // Faces steeper than ~35 degrees hold no soil or snow.
                const double steep = std::clamp((slope - 0.45) / 0.5, 0.0, 1.0);
                c = glm::mix(c, rock, steep);
                for (int k = 0; k < 3; ++k) out.at(x, y, k) = static_cast<float>(c[k]);
            }
    });
    return out;
}

Image demColour(const Image& heights, glm::dvec2 extent, std::optional<Image> texture, const std::string& textureName) {
    if (!texture) {
        Image ramp = terrainColours(heights, extent);
        for (float& v : ramp.pixels) v = srgbDisplayToLinear(v);
        return ramp;
    }
    if (texture->width == heights.width && texture->height == heights.height) return std::move(*texture);
    if (texture->width < heights.width || texture->height < heights.height)
        throw Error(ErrorCode::InvalidArgument, "colour texture " + textureName + " (" + std::to_string(texture->width) + "x" +
                                                    std::to_string(texture->height) + ") is smaller than the DEM (" +
                                                    std::to_string(heights.width) + "x" + std::to_string(heights.height) + ")");
    return areaDownsample(*texture, heights.width, heights.height);
}

glm::dvec2 fieldExtent(const GroundParams& params) {
    checkGroundParams(params);
    return {2.0 * halfWidth(params.eyeHeight, params.near, params.far, params.fovDegrees), params.far - params.near};
}

double fovForFieldWidth(double eyeHeight, double near, double far, double width) {
    GroundParams p{eyeHeight, near, far, 60.0};
    checkGroundParams(p);
    const double perTan = halfWidth(eyeHeight, near, far, 90.0);  // tan(45 degrees) = 1
    const double fov = 2.0 * std::atan(0.5 * width / perTan) * 180.0 / kPi;
    if (!(fov > 0.0 && fov < 170.0))
        throw Error(ErrorCode::InvalidArgument, "a field " + std::to_string(width) +
                                                    " wide needs a field of view of " + std::to_string(fov) +
                                                    " degrees, outside (0, 170)");
    return fov;
}

GroundParams groundForField(const TerrainViewer& viewer, glm::dvec2 fieldMetres) {
    constexpr double kDefaultFar = 6000.0, kDefaultFov = 60.0;
    GroundParams ground;
    ground.eyeHeight = viewer.eyeHeight;
    ground.near = viewer.near;
    ground.far = viewer.far > 0 ? viewer.far : fieldMetres.y > 0 ? viewer.near + fieldMetres.y : kDefaultFar;
    ground.fovDegrees = viewer.fovDegrees > 0 ? viewer.fovDegrees
                        : fieldMetres.x > 0   ? fovForFieldWidth(viewer.eyeHeight, viewer.near, ground.far, fieldMetres.x)
                                              : kDefaultFov;
    return ground;
}

format::ConusFile encodeHeightField(const Image& heights, const Image& colour,
                                    const HeightFieldOptions& options) {
    constexpr const char* kWhat = "encodeHeightField";
    checkGroundParams(options.ground);
    checkSize(options.width, options.height, kWhat);
    if (options.mapGrid < 2 || options.mapGrid > kMaxMapSide)
        throw Error(ErrorCode::InvalidArgument,
                    std::string(kWhat) + ": map grid " + std::to_string(options.mapGrid) + " is outside [2, " + std::to_string(kMaxMapSide) + "]");
    const Image source = combine(heights, colour, kWhat);

    // Sample through a grid as fine as the image: a sample then sits where the analytic inverse
    // puts it (the piecewise-bilinear error of a coarse grid would shift the mesh's vertices).
    GroundParams ground = options.ground;
    if (options.fitRows && ground.rows.empty()) ground.rows = groundRowsForTerrain(heights, ground, options.height);
    const int fine = std::clamp(std::max(options.width, options.height) + 1, options.mapGrid, kMaxMapSide);
    const SamplingMap sampling = buildGroundMap(ground, fine, fine);
    EncodeOptions encode;
    encode.width = options.width;
    encode.height = options.height;
    encode.threads = options.threads;
    encode.progress = options.progress;

    format::ConusFile file;
    file.image = encodeImage(source, sampling, encode);
    file.pixelType = format::PixelType::Half;  // colour; Z is always FLOAT in the file
    file.sourceWidth = heights.width;
    file.sourceHeight = heights.height;
    file.dataKind = format::DataKind::HeightField;
    file.map = buildGroundMap(ground, options.mapGrid, options.mapGrid).toGrid();
    file.analytic = toAnalytic(ground);
    file.depth = heightDepth(file.image, options.units);
    return file;
}

format::ConusFile encodeHeightField(const Image& heights, const Image& colour, const SamplingMap& map, int width,
                                    int height, const std::string& units, int threads) {
    constexpr const char* kWhat = "encodeHeightField";
    checkSize(width, height, kWhat);
    EncodeOptions encode;
    encode.width = width;
    encode.height = height;
    encode.threads = threads;
    format::ConusFile file;
    file.image = encodeImage(combine(heights, colour, kWhat), map, encode);
    file.pixelType = format::PixelType::Half;  // colour; Z is always FLOAT in the file
    file.sourceWidth = heights.width;
    file.sourceHeight = heights.height;
    file.dataKind = format::DataKind::HeightField;
    file.map = map.toGrid();
    file.depth = heightDepth(file.image, units);
    return file;
}

format::ConusFile uniformHeightField(const Image& heights, const Image& colour, int width, int height,
                                     const std::string& units, int threads) {
    constexpr const char* kWhat = "uniformHeightField";
    checkSize(width, height, kWhat);
    const Image source = combine(heights, colour, kWhat);
    format::ConusFile file;
    file.image = width == source.width && height == source.height ? source
                                                                  : areaDownsample(source, width, height, threads);
    file.pixelType = format::PixelType::Half;
    file.sourceWidth = heights.width;
    file.sourceHeight = heights.height;
    file.dataKind = format::DataKind::HeightField;
    file.map = SamplingMap::identity(2, 2).toGrid();
    file.depth = heightDepth(file.image, units);
    return file;
}

Mesh undistortHeightField(const format::ConusFile& file, glm::dvec2 extent) {
    constexpr const char* kWhat = "undistortHeightField";
    const Image& image = file.image;
    checkImage(image, kWhat);
    const int z = image.channelIndex("Z");
    if (z < 0) throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": the CoNUS image has no Z channel");
    if (!(extent.x > 0 && extent.y > 0 && std::isfinite(extent.x) && std::isfinite(extent.y)))
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": field extent " + std::to_string(extent.x) +
                                                    " x " + std::to_string(extent.y) + " is not positive");
    int rgb[3] = {image.channelIndex("R"), image.channelIndex("G"), image.channelIndex("B")};

    std::optional<GroundParams> ground;
    std::optional<SamplingMap> grid;
    if (file.analytic && file.analytic->is(format::MapKind::Ground))
        ground = groundFromAnalytic(*file.analytic);
    else
        grid = SamplingMap::fromGrid(file.map);

    // Vertex columns: the field's left edge, every pixel centre, the right edge (rows likewise).
    const int w = image.width, h = image.height, nx = w + 2, ny = h + 2;
    const auto coordinate = [](int i, int n) { return i == 0 ? 0.0 : i == n + 1 ? 1.0 : (i - 0.5) / n; };
    Mesh mesh;
    const std::size_t count = static_cast<std::size_t>(nx) * ny;
    mesh.positions.resize(count);
    mesh.colours.resize(count);
    parallelRows(ny, 0, [&](int j0, int j1) {
        for (int j = j0; j < j1; ++j) {
            const int py = std::clamp(j - 1, 0, h - 1);
            for (int i = 0; i < nx; ++i) {
                const int px = std::clamp(i - 1, 0, w - 1);
                const glm::dvec2 pd(coordinate(i, w), coordinate(j, h));
                const glm::dvec2 p = ground ? groundUndistort(*ground, pd) : grid->undistort(pd);
                const std::size_t k = static_cast<std::size_t>(j) * nx + i;
                mesh.positions[k] = glm::vec3(float(p.x * extent.x), image.at(px, py, z), float(p.y * extent.y));
                for (int c = 0; c < 3; ++c)
                    mesh.colours[k][c] = rgb[c] >= 0 ? image.at(px, py, rgb[c]) : 0.7f;
            }
        }
    });
    mesh.indices.reserve(static_cast<std::size_t>(nx - 1) * (ny - 1) * 6);
    for (int j = 0; j + 1 < ny; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            const auto k = static_cast<std::uint32_t>(j * nx + i), right = k + 1, below = k + nx;
            // Counter-clockwise seen from +y (x right, z toward the viewer).
            mesh.indices.insert(mesh.indices.end(), {k, below, right, right, below, below + 1});
        }
    addNormals(mesh);
    return mesh;
}

Mesh undistortHeightField(const format::ConusFile& file) {
    if (!file.analytic || !file.analytic->is(format::MapKind::Ground))
        throw Error(ErrorCode::InvalidArgument,
                    "undistortHeightField: the file has no ground-map parameters to size the field; give its extent");
    return undistortHeightField(file, fieldExtent(groundFromAnalytic(*file.analytic)));
}

double heightAt(const format::ConusFile& file, glm::dvec2 p) {
    const Image& image = file.image;
    checkImage(image, "heightAt");
    const int z = image.channelIndex("Z");
    if (z < 0) throw Error(ErrorCode::InvalidArgument, "heightAt: the CoNUS image has no Z channel");
    const glm::dvec2 pd = file.analytic && file.analytic->is(format::MapKind::Ground)
                              ? groundDistort(groundFromAnalytic(*file.analytic), p)
                              : SamplingMap::fromGrid(file.map).distort(p);
    const double fx = std::clamp(pd.x * image.width - 0.5, 0.0, image.width - 1.0);
    const double fy = std::clamp(pd.y * image.height - 0.5, 0.0, image.height - 1.0);
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    const int x1 = std::min(x0 + 1, image.width - 1), y1 = std::min(y0 + 1, image.height - 1);
    const double sx = fx - x0, sy = fy - y0;
    const double top = image.at(x0, y0, z) + sx * (image.at(x1, y0, z) - image.at(x0, y0, z));
    const double bottom = image.at(x0, y1, z) + sx * (image.at(x1, y1, z) - image.at(x0, y1, z));
    return top + sy * (bottom - top);
}

}  // namespace conus::codec
