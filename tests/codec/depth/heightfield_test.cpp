#include "conus/codec/depth/heightfield.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "conus/codec/builders/ground_map.h"
#include "conus/format/container.h"
#include "conus/core/display.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

// Metres: eye 150 m up, the field from 50 m to 6 km in front of the viewer.
GroundParams testGround() { return {150.0, 50.0, 6000.0, 60.0}; }

TerrainOptions smallTerrain(int size = 256) {
    TerrainOptions o;
    o.width = o.height = size;
    o.seed = 3;
    return o;
}

format::ConusFile encodeSmall(int size, int conus) {
    const Image dem = generateTerrain(smallTerrain(size));
    const Image colour = terrainColours(dem, fieldExtent(testGround()));
    HeightFieldOptions options;
    options.ground = testGround();
    options.width = options.height = conus;
    options.mapGrid = 33;
    return encodeHeightField(dem, colour, options);
}

TEST(HeightFieldTerrain, DeterministicAndSizeIndependent) {
    const Image a = generateTerrain(smallTerrain(128));
    const Image b = generateTerrain(smallTerrain(128));
    EXPECT_EQ(a.pixels, b.pixels);
    TerrainOptions other = smallTerrain(128);
    other.seed = 4;
    EXPECT_NE(a.pixels, generateTerrain(other).pixels);
    // The same landscape at twice the size: pixel (2x+1/2) of the large one sits between samples;
    // compare the sample at the same (u,v) instead: large pixel centres (2x+0.5)/256 vs (x+0.5)/128
    // differ by a quarter of a small pixel, so heights agree to the local slope only.
    const Image big = generateTerrain(smallTerrain(256));
    double diff = 0;
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x) {
            const double avg = 0.25 * (big.at(2 * x, 2 * y) + big.at(2 * x + 1, 2 * y) + big.at(2 * x, 2 * y + 1) +
                                       big.at(2 * x + 1, 2 * y + 1));
            diff += std::abs(avg - a.at(x, y));
        }
    EXPECT_LT(diff / (128 * 128), 10.0);  // metres, on ~600 m of relief
    const auto [lo, hi] = std::minmax_element(a.pixels.begin(), a.pixels.end());
    EXPECT_GE(*lo, 0.0f);
    EXPECT_GT(*hi - *lo, 200.0f);
}

TEST(HeightFieldTerrain, ColoursInRange) {
    const Image dem = generateTerrain(smallTerrain(64));
    const Image colour = terrainColours(dem, {1000, 1000});
    ASSERT_EQ(colour.channels, (std::vector<std::string>{"R", "G", "B"}));
    for (float c : colour.pixels) {
        EXPECT_GE(c, 0.0f);
        EXPECT_LE(c, 1.0f);
    }
}

// With no texture the ramp is made linear by the sRGB curve (display 0.5 is 0.2140 of the light,
// the linear toe below 0.04045 is v / 12.92); a texture is kept at the DEM's size, averaged down
// from a larger one (each sample the mean of the block of texels it covers) and refused when
// smaller, naming it.
TEST(HeightFieldTerrain, DemColourIsLinearRampOrTheTextureAtTheDemsSize) {
    const Image dem = generateTerrain(smallTerrain(16));
    const glm::dvec2 extent{900, 700};
    const Image ramp = terrainColours(dem, extent), linear = demColour(dem, extent);
    ASSERT_EQ(linear.channels, ramp.channels);
    ASSERT_EQ(linear.pixels.size(), ramp.pixels.size());
    for (std::size_t i = 0; i < ramp.pixels.size(); ++i) {
        const double v = ramp.pixels[i];
        const double want = v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
        ASSERT_NEAR(linear.pixels[i], want, 1e-7) << i;
        ASSERT_LT(linear.pixels[i], v + 1e-7) << "light is never above its display value";
    }
    EXPECT_NEAR(srgbDisplayToLinear(0.5f), 0.214041, 1e-6);
    EXPECT_FLOAT_EQ(srgbDisplayToLinear(0.03f), 0.03f / 12.92f);

    Image texture = makeImage(32, 16, {"R", "G", "B"});
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 32; ++x)
            for (int c = 0; c < 3; ++c) texture.at(x, y, c) = float(x + 100 * y + 1000 * c);
    const Image small = generateTerrain(smallTerrain(8));  // 8x8: the texture is 4x wider, 2x taller
    const Image down = demColour(small, extent, texture, "ortho.png");
    ASSERT_EQ(down.width, 8);
    ASSERT_EQ(down.height, 8);
    // Each DEM sample covers 4 x 2 texels: x 4i..4i+3 (mean 4i + 1.5), y 2j..2j+1 (mean 2j + 0.5).
    EXPECT_NEAR(down.at(3, 5, 1), 1000 + (4 * 3 + 1.5) + 100 * (2 * 5 + 0.5), 1e-3);
    try {
        demColour(generateTerrain(smallTerrain(32)), extent, texture, "ortho.png");  // 32x16 under 32x32
        ADD_FAILURE() << "a texture smaller than the DEM was taken";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
        EXPECT_NE(std::string(e.what()).find("ortho.png (32x16) is smaller than the DEM (32x32)"), std::string::npos) << e.what();
    }
    TerrainOptions wide = smallTerrain();
    wide.width = 32;
    wide.height = 16;
    EXPECT_EQ(demColour(generateTerrain(wide), extent, texture, "ortho.png").pixels, texture.pixels) << "the DEM's size: as it is";
}

// The viewer a user gives, completed from the field's size in metres: far to its far edge, the
// field of view to its width there; the defaults where the size is unknown; what was given kept.
TEST(HeightFieldGround, TheViewerIsCompletedFromTheFieldsSize) {
    const TerrainViewer viewer{120.0, 300.0, 0.0, 0.0};
    const GroundParams fitted = groundForField(viewer, {5000.0, 3500.0});
    EXPECT_EQ(fitted.eyeHeight, 120.0);
    EXPECT_EQ(fitted.near, 300.0);
    EXPECT_DOUBLE_EQ(fitted.far, 3800.0);
    EXPECT_NEAR(fieldExtent(fitted).x, 5000.0, 1e-6);
    const GroundParams unknown = groundForField(viewer, {0.0, 0.0});
    EXPECT_EQ(unknown.far, 6000.0);
    EXPECT_EQ(unknown.fovDegrees, 60.0);
    const GroundParams given = groundForField({120.0, 300.0, 900.0, 45.0}, {5000.0, 3500.0});
    EXPECT_EQ(given.far, 900.0);
    EXPECT_EQ(given.fovDegrees, 45.0);
    EXPECT_THROW(groundForField(viewer, {1e9, 100.0}), Error);  // no field of view spans it
}

TEST(HeightFieldEncode, ValidFileWithHeightAndGroundParams) {
    const format::ConusFile file = encodeSmall(256, 64);
    const format::ValidationReport report = format::validateConusFile(file);
    EXPECT_TRUE(report.ok()) << report.str();
    EXPECT_EQ(file.dataKind, format::DataKind::HeightField);
    EXPECT_EQ(file.depth.kind, format::DepthKind::Height);
    EXPECT_EQ(file.depth.units, "m");
    EXPECT_LT(file.depth.near, file.depth.far);
    EXPECT_GE(file.image.channelIndex("Z"), 0);
    EXPECT_GE(file.image.channelIndex("R"), 0);
    ASSERT_TRUE(file.analytic.has_value());
    EXPECT_EQ(file.analytic->kind, "ground");
    const GroundParams back = groundFromAnalytic(*file.analytic);
    EXPECT_EQ(back.far, testGround().far);
    EXPECT_EQ(file.map.columns, 33);
    EXPECT_EQ(file.sourceWidth, 256);

    // And through a file on disk.
    const std::string path = (std::filesystem::temp_directory_path() / "conus_heightfield_test.exr").string();
    format::writeConusFile(path, file);
    const format::ValidationReport disk = format::validateConusFile(path);
    EXPECT_TRUE(disk.ok()) << disk.str();
    const format::ConusFile read = format::readConusFile(path);
    EXPECT_EQ(read.depth.kind, format::DepthKind::Height);
    EXPECT_EQ(read.image.channelIndex("Z") >= 0, true);
    std::filesystem::remove(path);
}

TEST(HeightFieldEncode, ZIsFilteredHeight) {
    // A flat DEM at 42 m stays 42 m everywhere: filtering never invents heights.
    Image dem = makeImage(64, 64, {"Z"});
    std::fill(dem.pixels.begin(), dem.pixels.end(), 42.0f);
    HeightFieldOptions options;
    options.ground = testGround();
    options.width = options.height = 32;
    const format::ConusFile file = encodeHeightField(dem, terrainColours(dem, {100, 100}), options);
    const int z = file.image.channelIndex("Z");
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) EXPECT_NEAR(file.image.at(x, y, z), 42.0f, 1e-3);
    EXPECT_TRUE(format::validateConusFile(file).ok());
}

TEST(HeightFieldMesh, VerticesOnUndistortedGround) {
    const format::ConusFile file = encodeSmall(128, 48);
    const GroundParams ground = groundFromAnalytic(*file.analytic);  // with the rows fitted to the terrain
    ASSERT_FALSE(ground.rows.empty());
    const glm::dvec2 extent = fieldExtent(ground);
    const Mesh mesh = undistortHeightField(file);
    const int w = file.image.width, h = file.image.height, nx = w + 2, ny = h + 2;
    ASSERT_EQ(mesh.positions.size(), std::size_t(nx) * ny);
    ASSERT_EQ(mesh.colours.size(), mesh.positions.size());
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    ASSERT_EQ(mesh.indices.size(), std::size_t(nx - 1) * (ny - 1) * 6);
    const int z = file.image.channelIndex("Z");
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::dvec2 p = groundUndistort(ground, {(x + 0.5) / w, (y + 0.5) / h});
            const glm::vec3 q = mesh.positions[std::size_t(y + 1) * nx + x + 1];
            ASSERT_NEAR(q.x / extent.x, p.x, 1e-6) << x << "," << y;
            ASSERT_NEAR(q.z / extent.y, p.y, 1e-6) << x << "," << y;
            ASSERT_EQ(q.y, file.image.at(x, y, z));
        }
    // The corners of the field are covered exactly.
    const auto corner = [&](int i, int j) { return mesh.positions[std::size_t(j) * nx + i]; };
    EXPECT_EQ(corner(0, 0).x, 0.0f);
    EXPECT_EQ(corner(0, 0).z, 0.0f);
    EXPECT_NEAR(corner(nx - 1, ny - 1).x, extent.x, 1e-3);
    EXPECT_NEAR(corner(nx - 1, ny - 1).z, extent.y, 1e-3);
    EXPECT_NEAR(corner(nx - 1, 0).x, extent.x, 1e-3);
    EXPECT_NEAR(corner(0, ny - 1).z, extent.y, 1e-3);
    for (const glm::vec3& n : mesh.normals) ASSERT_GT(n.y, 0.0f);
}

TEST(HeightFieldMesh, GridUndistortWithoutAnalytic) {
    format::ConusFile file = encodeSmall(128, 32);
    const glm::dvec2 extent = fieldExtent(testGround());
    file.analytic.reset();
    const Mesh viaGrid = undistortHeightField(file, extent);
    const SamplingMap map = SamplingMap::fromGrid(file.map);
    const glm::dvec2 p = map.undistort({10.5 / 32, 20.5 / 32});
    EXPECT_NEAR(viaGrid.positions[std::size_t(21) * 34 + 11].x / extent.x, p.x, 1e-6);
    EXPECT_THROW(undistortHeightField(file), Error);
}

TEST(HeightFieldMesh, DenserNearSparserFar) {
    const int size = 64;
    const Image dem = generateTerrain(smallTerrain(256));
    const GroundParams ground = testGround();
    const glm::dvec2 extent = fieldExtent(ground);
    const Image colour = terrainColours(dem, extent);
    HeightFieldOptions options;
    options.ground = ground;
    options.width = options.height = size;
    const Mesh conus = undistortHeightField(encodeHeightField(dem, colour, options));
    const Mesh uniform = undistortHeightField(uniformHeightField(dem, colour, size, size), extent);
    const glm::dvec2 viewer(0.5 * extent.x, extent.y + ground.near);
    const auto within = [&](const Mesh& m, double lo, double hi) {
        int count = 0;
        for (const glm::vec3& p : m.positions) {
            const double d = glm::length(glm::dvec2(p.x, p.z) - viewer);
            count += d >= lo && d < hi;
        }
        return count;
    };
    const int nearConus = within(conus, 0, 1000), nearUniform = within(uniform, 0, 1000);
    const int farConus = within(conus, 4000, 1e9), farUniform = within(uniform, 4000, 1e9);
    EXPECT_GT(nearConus, 3 * nearUniform) << nearConus << " vs " << nearUniform;
    EXPECT_LT(farConus, farUniform) << farConus << " vs " << farUniform;
}

// A plain near the viewer and a ridge far away: the planar rows give the ridge the few rows flat
// ground would cover there; the fitted rows give it the rows it covers on screen.
TEST(HeightFieldRows, AFarRidgeGetsTheRowsItCoversOnScreen) {
    Image dem = makeImage(64, 256, {"Z"});
    for (int y = 0; y < dem.height; ++y)
        for (int x = 0; x < dem.width; ++x) dem.at(x, y, 0) = y < 64 ? 600.0f * std::sin(3.14159f * y / 64) : 0.0f;
    const GroundParams ground = testGround();
    const std::vector<double> rows = groundRowsForTerrain(dem, ground, 64);
    ASSERT_GE(rows.size(), 2u);
    GroundParams fitted = ground;
    fitted.rows = rows;
    EXPECT_NO_THROW(checkGroundParams(fitted));
    // The far quarter (v < 0.25, the ridge, its back hidden) holds several times the rows planar
    // gives it, and a good share of the image.
    const double planarFar = groundDistort(ground, {0.5, 0.25}).y, fittedFar = groundDistort(fitted, {0.5, 0.25}).y;
    EXPECT_GT(fittedFar, 0.15);
    EXPECT_GT(fittedFar, 4 * planarFar) << fittedFar << " vs " << planarFar;
    // No band is sampled finer than the DEM's own rows (256 over 64 CoNUS rows: 4x) or coarser
    // than a quarter of uniform.
    for (std::size_t k = 1; k < rows.size(); ++k) {
        const double density = (rows[k] - rows[k - 1]) * double(rows.size() - 1);
        EXPECT_LE(density, 4.0 * 1.001) << k;
        EXPECT_GE(density, 0.25 * 0.999) << k;
    }
    // The map is exactly invertible and never folds.
    for (double v = 0; v <= 1.0; v += 1.0 / 97)
        for (double u = 0; u <= 1.0; u += 1.0 / 13) {
            const glm::dvec2 back = groundUndistort(fitted, groundDistort(fitted, {u, v}));
            EXPECT_NEAR(back.x, u, 1e-9);
            EXPECT_NEAR(back.y, v, 1e-9);
        }
    EXPECT_TRUE(format::validateGrid(buildGroundMap(fitted, 65, 65).toGrid()).ok());
}

TEST(HeightFieldRows, TheProfileTravelsInTheFileAndBadProfilesAreRefused) {
    const format::ConusFile file = encodeSmall(256, 64);
    ASSERT_TRUE(file.analytic && !file.analytic->groundRows.empty());
    const std::string path = (std::filesystem::temp_directory_path() / "conus_heightfield_rows_test.exr").string();
    format::writeConusFile(path, file);
    const format::ConusFile read = format::readConusFile(path);
    std::filesystem::remove(path);
    ASSERT_TRUE(read.analytic.has_value());
    EXPECT_EQ(read.analytic->groundRows, file.analytic->groundRows);
    EXPECT_EQ(groundFromAnalytic(*read.analytic).rows, groundFromAnalytic(*file.analytic).rows);

    format::ConusFile bad = file;
    std::swap(bad.analytic->groundRows[3], bad.analytic->groundRows[4]);
    EXPECT_FALSE(format::validateConusFile(bad).ok());
    EXPECT_THROW(groundFromAnalytic(*bad.analytic), Error);
    bad = file;
    bad.analytic->groundRows.back() = 0.9f;
    EXPECT_FALSE(format::validateConusFile(bad).ok());
    bad = file;
    bad.analytic->kind = "foci";
    EXPECT_NE(format::validateConusFile(bad).str().find("conus:groundRows belongs to a ground map"), std::string::npos);

    // The planar rows when asked: no profile in the file.
    const Image dem = generateTerrain(smallTerrain(128));
    HeightFieldOptions options;
    options.ground = testGround();
    options.width = options.height = 32;
    options.fitRows = false;
    EXPECT_TRUE(encodeHeightField(dem, terrainColours(dem, fieldExtent(testGround())), options).analytic->groundRows.empty());
}

TEST(HeightFieldExtent, FovForWidthInvertsFieldExtent) {
    const GroundParams g = testGround();
    const double width = fieldExtent(g).x;
    EXPECT_NEAR(fovForFieldWidth(g.eyeHeight, g.near, g.far, width), g.fovDegrees, 1e-9);
    EXPECT_THROW(fovForFieldWidth(g.eyeHeight, g.near, g.far, 1e9), Error);
}

TEST(HeightFieldEncode, RejectsBadInput) {
    Image dem = makeImage(16, 16, {"Z"});
    HeightFieldOptions options;
    options.ground = testGround();
    options.width = options.height = 8;
    EXPECT_THROW(encodeHeightField(dem, makeImage(8, 8, {"R", "G", "B"}), options), Error);
    dem.at(3, 3) = std::nanf("");
    EXPECT_THROW(encodeHeightField(dem, makeImage(16, 16, {"R", "G", "B"}), options), Error);
    options.width = 0;
    EXPECT_THROW(encodeHeightField(dem, makeImage(16, 16, {"R", "G", "B"}), options), Error);
}

}  // namespace
}  // namespace conus::codec

namespace conus::codec {
namespace {

// A DEM argument that names the procedural terrain: its size and seed, the defaults where left out;
// anything else is a file's name; past the sample limit refused.
TEST(HeightFieldTerrain, ProceduralArgumentsNameTheTerrain) {
    const TerrainOptions defaults;
    const auto plain = proceduralTerrain("procedural");
    ASSERT_TRUE(plain);
    EXPECT_EQ(plain->width, defaults.width);
    EXPECT_EQ(plain->seed, defaults.seed);
    const auto sized = proceduralTerrain("procedural:300:7");
    ASSERT_TRUE(sized);
    EXPECT_EQ(sized->width, 300);
    EXPECT_EQ(sized->height, 300);
    EXPECT_EQ(sized->seed, 7u);
    EXPECT_EQ(proceduralTerrain("procedural:64")->seed, defaults.seed);
    EXPECT_FALSE(proceduralTerrain("dem.tif"));
    EXPECT_FALSE(proceduralTerrain("procedural.tif"));
    EXPECT_FALSE(proceduralTerrain("procedural:x"));
    EXPECT_THROW(proceduralTerrain("procedural:999999"), Error);
}

}  // namespace
}  // namespace conus::codec
