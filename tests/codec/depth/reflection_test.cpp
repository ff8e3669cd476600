#include "conus/codec/depth/reflection.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "codec/mesh/mesh_test_scenes.h"
#include "conus/codec/mesh/shading.h"
#include "conus/core/error.h"
#include "conus/format/container.h"
#include "conus/format/reflection_asset.h"
#include "test_dir.h"

namespace conus::codec {
namespace {

using test::flatBox;
using test::hitBox;

// Mirror z = 0 facing +z; the box in front of it, off every axis so nothing lines up by chance.
const glm::dvec3 kBoxLo(0.4, -0.3, 1.5), kBoxHi(1.0, 0.5, 2.2);
const glm::dvec3 kEye(-1.2, 0.1, 3.0);

glm::dvec3 mirrorZ(glm::dvec3 p) { return {p.x, p.y, -p.z}; }

Reflector planeMirror() { return test::planeMirrorZ(3.0); }

std::vector<ReflectionFace> bakeBox(int size, bool uniform) {
    static const MeshScene scene(flatBox(glm::vec3(kBoxLo), glm::vec3(kBoxHi)));
    ReflectionBakeOptions o;
    o.centre = {0.0, 0.0, 0.0};
    o.size = size;
    o.uniform = uniform;
    o.magnification = 3.0;
    return bakeReflection(scene, o);
}

struct Errors {
    int checked = 0, missed = 0;
    double sum = 0, max = 0;
};

// Eye rays aimed at points of the mirror-image box's faces seen from the mirror's centre (its
// near face z = -1.5 and its side x = 0.4, inset so no ray grazes an edge): the reflected hit must
// be the mirror image of where the straight ray meets the mirror-image box.
Errors mirrorErrors(const std::vector<ReflectionFace>& faces, int rays, unsigned seed) {
    const glm::dvec3 imageLo = glm::min(mirrorZ(kBoxLo), mirrorZ(kBoxHi)), imageHi = glm::max(mirrorZ(kBoxLo), mirrorZ(kBoxHi));
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> inset(0.12, 0.88);
    const Reflector mirror = planeMirror();
    Errors e;
    while (e.checked + e.missed < rays) {
        const glm::dvec3 target(imageLo.x + inset(random) * (imageHi.x - imageLo.x),
                                imageLo.y + inset(random) * (imageHi.y - imageLo.y),
                                imageLo.z + inset(random) * (imageHi.z - imageLo.z));
        const Ray eye{kEye, glm::normalize(target - kEye)};
        const auto expected = hitBox(eye, imageLo, imageHi);
        if (!expected || expected->axis == 1) continue;  // the y faces are hidden from the centre
        if (hitBox(eye, kBoxLo, kBoxHi)) continue;        // the real box in the way
        const auto onMirror = hitReflector(mirror, eye);
        if (!onMirror) continue;
        const glm::dvec3 want = mirrorZ(eye.origin + eye.direction * expected->t);
        const auto got = traceReflection(faces, onMirror->reflected);
        if (!got) {
            ++e.missed;
            continue;
        }
        const double error = glm::distance(got->hit.position, want);
        // The path's length is kept by the mirror: eye -> mirror -> hit = the straight ray's t.
        EXPECT_NEAR(onMirror->t + got->hit.t, expected->t, error + 1e-9);
        e.sum += error;
        e.max = std::max(e.max, error);
        ++e.checked;
    }
    return e;
}

TEST(Reflection, PlaneMirrorReflectsByTheLaw) {
    const Reflector mirror = planeMirror();
    const Ray eye{kEye, glm::normalize(glm::dvec3(0.3, -0.2, 0.0) - kEye)};
    const auto hit = hitReflector(mirror, eye);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->reflected.origin.x, 0.3, 1e-12);
    EXPECT_NEAR(hit->reflected.origin.y, -0.2, 1e-12);
    EXPECT_NEAR(hit->reflected.origin.z, 0.0, 1e-12);
    const glm::dvec3 d = eye.direction, r = hit->reflected.direction;
    EXPECT_NEAR(r.x, d.x, 1e-12);
    EXPECT_NEAR(r.y, d.y, 1e-12);
    EXPECT_NEAR(r.z, -d.z, 1e-12);
    // The back of the mirror and beyond its edge reflect nothing.
    EXPECT_FALSE(hitReflector(mirror, Ray{{0, 0, -2}, {0, 0, 1}}));
    EXPECT_FALSE(hitReflector(mirror, Ray{{3.5, 0, 2}, {0, 0, -1}}));
}

TEST(Reflection, SphereReflectsAboutItsNormal) {
    Reflector sphere;
    sphere.centre = {0.2, -0.1, 0.3};
    sphere.radius = 0.7;
    std::mt19937 random(7);
    std::uniform_real_distribution<double> offset(-0.6, 0.6);
    for (int i = 0; i < 200; ++i) {
        const glm::dvec3 origin(1.5, 2.0, 4.0);
        const Ray eye{origin, glm::normalize(sphere.centre + glm::dvec3(offset(random), offset(random), 0) - origin)};
        const auto hit = hitReflector(sphere, eye);
        if (!hit) continue;
        EXPECT_NEAR(glm::distance(hit->reflected.origin, sphere.centre), sphere.radius, 1e-9);
        EXPECT_NEAR(glm::length(hit->reflected.direction), 1.0, 1e-12);
        // Angle in = angle out, in the plane of the ray and the normal.
        EXPECT_NEAR(glm::dot(hit->reflected.direction, hit->normal), -glm::dot(eye.direction, hit->normal), 1e-9);
        EXPECT_NEAR(glm::dot(glm::cross(eye.direction, hit->normal), hit->reflected.direction), 0.0, 1e-9);
        EXPECT_LT(glm::dot(eye.direction, hit->normal), 0.0);
    }
    EXPECT_FALSE(hitReflector(sphere, Ray{{5, 5, 5}, {1, 0, 0}}));
}

TEST(Reflection, CubeFacesCoverEveryDirectionOnce) {
    std::mt19937 random(3);
    std::normal_distribution<double> n;
    for (int i = 0; i < 500; ++i) {
        const glm::dvec3 d = glm::normalize(glm::dvec3(n(random), n(random), n(random)));
        int seen = 0;
        for (int f = 0; f < kCubeFaces; ++f) {
            const glm::dvec3 q = cubeFaceCamera({1, 2, 3}, f, 0.1, 10).project(glm::dvec3(1, 2, 3) + d);
            if (q.z > 0 && q.x > 0 && q.x < 1 && q.y > 0 && q.y < 1) ++seen;
        }
        EXPECT_EQ(seen, 1);
    }
    EXPECT_THROW(cubeFaceCamera({0, 0, 0}, 6, 0.1, 1), Error);
}

TEST(Reflection, PlaneMirrorHitsAreTheMirrorImageOfTheBox) {
    const auto faces = bakeReflection(MeshScene(flatBox(glm::vec3(kBoxLo), glm::vec3(kBoxHi))), [] {
        ReflectionBakeOptions o;
        o.size = 128;
        return o;
    }());
    ASSERT_EQ(faces.size(), std::size_t(kCubeFaces));
    const Errors e = mirrorErrors(faces, 300, 11);
    EXPECT_EQ(e.missed, 0);
    // A texel of a 90-degree face 128 wide, 2 units away, is about 0.03 wide.
    EXPECT_LT(e.sum / e.checked, 0.01);
    EXPECT_LT(e.max, 0.05);
    // Reflected rays that leave past the box meet only the far planes: no hit.
    const Reflector mirror = planeMirror();
    const auto away = hitReflector(mirror, Ray{kEye, glm::normalize(glm::dvec3(-2.0, 0.5, 0.0) - kEye)});
    ASSERT_TRUE(away);
    EXPECT_FALSE(traceReflection(faces, away->reflected));
}

TEST(Reflection, FocusedFacesBeatUniformOnTheBoxAtEqualTexels) {
    const Errors conus = mirrorErrors(bakeBox(48, false), 300, 5);
    const Errors uniform = mirrorErrors(bakeBox(48, true), 300, 5);
    ASSERT_GT(conus.checked, 250);
    ASSERT_GT(uniform.checked, 250);
    EXPECT_LT(conus.sum / conus.checked, 0.8 * uniform.sum / uniform.checked);
}

TEST(Reflection, FocusSitsOnTheProjectedBox) {
    const Camera front = cubeFaceCamera({0, 0, 0}, 4, 0.01, 10);  // +z: sees the box
    const auto focus = reflectionFocus(front, {kBoxLo, kBoxHi}, 3.0);
    ASSERT_TRUE(focus);
    const glm::dvec3 centre = front.project(0.5 * (kBoxLo + kBoxHi));
    EXPECT_NEAR(focus->u, centre.x, 0.1);
    EXPECT_NEAR(focus->v, centre.y, 0.1);
    EXPECT_DOUBLE_EQ(focus->k, 3.0);
    EXPECT_FALSE(reflectionFocus(cubeFaceCamera({0, 0, 0}, 5, 0.01, 10), {kBoxLo, kBoxHi}, 3.0));  // -z: behind
}

TEST(Reflection, FocusIsTheDiscInscribedInTheProjectedBoxsSquare) {
    const Camera front = cubeFaceCamera({0, 0, 0}, 4, 0.01, 10);
    const auto focus = reflectionFocus(front, {kBoxLo, kBoxHi}, 4.0);
    ASSERT_TRUE(focus);
    glm::dvec2 lo(1e9), hi(-1e9);
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 q = front.project({c & 1 ? kBoxHi.x : kBoxLo.x, c & 2 ? kBoxHi.y : kBoxLo.y, c & 4 ? kBoxHi.z : kBoxLo.z});
        lo = glm::min(lo, glm::dvec2(q));
        hi = glm::max(hi, glm::dvec2(q));
    }
    EXPECT_NEAR(focus->r, 0.5 * std::max(hi.x - lo.x, hi.y - lo.y), 1e-12);
    EXPECT_LT(focus->r, 0.5 * glm::length(hi - lo));  // not the bounding disc
}

// The box before a wall whose top edge crosses the +z face with sky above: the face that holds the
// focus spends the sky's texels on the wall's outline against it (where reflected rays pass beside
// an edge with nothing stored behind it), not on the sky, unlike a focus over a flat context.
TEST(Reflection, FocusedFaceSpendsTheSkysTexelsOnItsOutline) {
    Mesh scene = flatBox(glm::vec3(kBoxLo), glm::vec3(kBoxHi));
    const Mesh wall = flatBox({-6.0f, -2.0f, 4.0f}, {6.0f, 1.5f, 4.3f});
    const auto base = static_cast<std::uint32_t>(scene.positions.size());
    scene.positions.insert(scene.positions.end(), wall.positions.begin(), wall.positions.end());
    scene.normals.insert(scene.normals.end(), wall.normals.begin(), wall.normals.end());
    for (std::uint32_t i : wall.indices) scene.indices.push_back(base + i);
    ReflectionBakeOptions bake;
    bake.size = 128;
    bake.roi = AxisBox{kBoxLo, kBoxHi};
    const std::vector<ReflectionFace> faces = bakeReflection(MeshScene(scene), bake);

    const Camera& front = faces[4].depth.camera();  // +z: the box, the wall and the sky
    FociOptions flat;
    flat.aspect = 1.0;
    flat.falloff = kFormatFalloff;
    const Focus focus = *reflectionFocus(front, *bake.roi, bake.magnification);
    const SamplingMap focusOnly = buildFociMap(std::span<const Focus>(&focus, 1), flat);
    const SamplingMap& map = faces[4].depth.map();
    // The wall's top edge on the side away from the focus (u > 0.5), and the sky well above it:
    // the outline's texels are finer across it (d v_d / d v) and denser, the sky's sparser.
    double outline = 0, outlineFlat = 0, sky = 0, skyFlat = 0;
    for (double x : {-3.0, -2.0, -1.0}) {
        SCOPED_TRACE(x);
        const glm::dvec2 edge(front.project({x, 1.5, 4.0})), above(front.project({x, 3.2, 4.0}));
        EXPECT_GT(map.jacobian(edge)[1][1], 1.35 * focusOnly.jacobian(edge)[1][1]);
        EXPECT_GT(map.jacobian(edge)[1][1], 1.5);
        outline += map.density(edge);
        outlineFlat += focusOnly.density(edge);
        sky += map.density(above);
        skyFlat += focusOnly.density(above);
    }
    EXPECT_GT(outline, 1.4 * outlineFlat);
    EXPECT_LT(sky, 0.7 * skyFlat);
    EXPECT_GT(reachedMagnification(map, std::span<const Focus>(&focus, 1))[0], 3.0);
    // The +x and -x faces see the wall's ends against the sky but not the box: they keep the identity.
    for (int f : {0, 1}) {
        const Image& image = faces[f].image;
        float most = 0, least = 1;  // coverage
        for (std::size_t i = kMeshChannelA; i < image.pixels.size(); i += image.channels.size())
            most = std::max(most, image.pixels[i]), least = std::min(least, image.pixels[i]);
        EXPECT_EQ(most - least, 1.0f);
        EXPECT_EQ(faces[f].depth.map().columns(), 2);
    }
}

// The hit's colour: bilinear between texel centres over the covered texels only.
TEST(Reflection, HitColourIsBilinearOverCoveredTexels) {
    ReflectionFace face = bakeBox(16, true)[0];
    Image& image = face.image;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            image.at(x, y, kMeshChannelR) = 0.1f * x;
            image.at(x, y, kMeshChannelR + 1) = 0.05f * y + 0.2f;
            image.at(x, y, kMeshChannelR + 2) = 0.5f;
            image.at(x, y, kMeshChannelA) = x == 9 ? 0.0f : 1.0f;  // column 9 saw nothing
        }
    DepthHit hit;
    // Between the centres of columns 3 and 4 (x = 3.5 + 0.3) and rows 5 and 6 (y = 5.5 + 0.25).
    hit.distorted = glm::dvec2(3.8 / 16.0, 5.75 / 16.0);
    hit.texel = {3, 5};
    glm::vec3 c = reflectionColour(face, hit);
    EXPECT_NEAR(c.r, 0.1 * 3.3, 1e-5);
    EXPECT_NEAR(c.g, 0.05 * 5.25 + 0.2, 1e-5);
    EXPECT_NEAR(c.b, 0.5, 1e-6);
    // Beside the uncovered column 9: only column 8 weighs, whatever the fraction toward 9.
    hit.distorted = glm::dvec2(8.9 / 16.0, 5.5 / 16.0);
    hit.texel = {8, 5};
    c = reflectionColour(face, hit);
    EXPECT_NEAR(c.r, 0.8, 1e-5);
    // All four uncovered: the hit's own texel.
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) image.at(x, y, kMeshChannelA) = 0.0f;
    hit.texel = {9, 5};
    EXPECT_NEAR(reflectionColour(face, hit).r, 0.9, 1e-6);
}

TEST(Reflection, BadBakeOptionsAreRefused) {
    const MeshScene scene(flatBox(glm::vec3(kBoxLo), glm::vec3(kBoxHi)));
    ReflectionBakeOptions o;
    o.size = 4;
    EXPECT_THROW(bakeReflection(scene, o), Error);
    o.size = 64;
    o.magnification = 0.5;
    EXPECT_THROW(bakeReflection(scene, o), Error);
    o.magnification = 2;
    o.centre = {std::nan(""), 0, 0};
    EXPECT_THROW(bakeReflection(scene, o), Error);
}

TEST(Reflection, FacesRoundTripThroughOneAssetFile) {
    const auto faces = bakeBox(32, false);
    conus::test::TestDir dir("reflection");
    const std::string path = dir.file("asset.exr");
    format::writeReflectionAsset(path, reflectionAssetFile(faces));
    EXPECT_TRUE(format::validateConusFile(path).ok()) << format::validateConusFile(path).str();
    const std::vector<ReflectionFace> back = readReflectionFaces(path);
    ASSERT_EQ(back.size(), faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f) {
        SCOPED_TRACE(kCubeFaceNames[f]);
        EXPECT_EQ(back[f].depth.depths(), faces[f].depth.depths());
        EXPECT_EQ(back[f].image.channels, faces[f].image.channels);
        EXPECT_EQ(back[f].image.pixels, faces[f].image.pixels);
        EXPECT_EQ(back[f].depth.map().nodes(), faces[f].depth.map().nodes());
        const glm::dvec3 p(0.7, 0.1, 1.8);
        const glm::dvec3 a = back[f].depth.camera().project(p), b = faces[f].depth.camera().project(p);
        EXPECT_NEAR(glm::distance(a, b), 0.0, 1e-4);
    }
    // The +z face sees the box, so its map is not the identity; -z sees nothing of it.
    EXPECT_GT(faces[4].depth.map().columns(), 2);
    EXPECT_EQ(faces[5].depth.map().columns(), 2);
    // The frame is the faces' eye and the world's axes.
    const format::ReflectionAssetFile asset = format::readReflectionAsset(path);
    EXPECT_EQ(asset.frame.centre, (std::array<float, 3>{0, 0, 0}));
    EXPECT_EQ(asset.frame.axes, (std::array<float, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
    EXPECT_THROW(reflectionAssetFile({faces[0]}), Error);
}

// Mean squared RGB error of `a` against `truth` over the pixels `inRegion` picks.
template <typename Pick>
double meanSquaredError(const Image& a, const Image& truth, Pick inRegion) {
    double sum = 0;
    int n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            if (!inRegion(x, y)) continue;
            for (int c = 0; c < 3; ++c) sum += (a.at(x, y, c) - truth.at(x, y, c)) * (a.at(x, y, c) - truth.at(x, y, c));
            ++n;
        }
    return n ? sum / (3.0 * n) : 0.0;
}

// CoNUS faces (the bake's defaults, a focus on the box) and uniform faces of 64 texels a side.
std::pair<std::vector<ReflectionFace>, std::vector<ReflectionFace>> bakeBoth(const MeshScene& mesh) {
    ReflectionBakeOptions bake;
    bake.size = 64;
    bake.roi = AxisBox{kBoxLo, kBoxHi};
    auto conus = bakeReflection(mesh, bake);
    bake.uniform = true;
    return {std::move(conus), bakeReflection(mesh, bake)};
}

TEST(Reflection, FramesMatchTheTracedReferenceAndCoNUSBeatsUniform) {
    // The box and a floor, a sphere mirror between them and the camera.
    const Mesh scene = test::rampedBoxAndFloor(glm::vec3(kBoxLo), glm::vec3(kBoxHi));
    const MeshScene mesh(scene);
    ReflectionFrameOptions o;
    o.reflector.centre = {0.0, 0.0, 0.0};
    o.reflector.radius = 0.5;
    const Camera camera = Camera::perspective({-0.8, 0.5, 3.0}, {0.0, 0.0, 0.0}, {0, 1, 0}, 22.0, 1.0, 0.1, 20.0);
    const Image truth = renderReflectionFrame(mesh, nullptr, o.reflector.centre, camera, 96, 96, o);
    // 64-texel faces: the box is a few texels across in the uniform ones. (At 32, with about 100
    // pixels on the box, one pixel either side of its outline decides the comparison.)
    const auto [conusFaces, uniformFaces] = bakeBoth(mesh);
    const Image conus = renderReflectionFrame(mesh, &conusFaces, o.reflector.centre, camera, 96, 96, o);
    const Image uniform = renderReflectionFrame(mesh, &uniformFaces, o.reflector.centre, camera, 96, 96, o);
    // The region of interest: reflector pixels whose traced reflected ray meets the box (its 12
    // triangles come first).
    std::vector<char> box(static_cast<std::size_t>(96) * 96, 0);
    int reflecting = 0, onBox = 0;
    for (int y = 0; y < truth.height; ++y)
        for (int x = 0; x < truth.width; ++x) {
            reflecting += truth.at(x, y, 3) == 2.0f;
            const auto mirror = hitReflector(o.reflector, camera.ray({(x + 0.5) / 96, (y + 0.5) / 96}));
            const auto hit = mirror ? mesh.intersect(mirror->reflected, 1e-6) : std::nullopt;
            onBox += box[static_cast<std::size_t>(y) * 96 + x] = hit && hit->triangle < 12;
        }
    ASSERT_GT(reflecting, 500);
    ASSERT_GT(onBox, 30);
    // Outside the reflector the frames are the same mesh render.
    EXPECT_EQ(meanSquaredError(conus, truth, [&](int x, int y) { return truth.at(x, y, 3) == 0.0f; }), 0.0);
    auto roi = [&](int x, int y) { return box[static_cast<std::size_t>(y) * 96 + x] != 0; };
    const double conusError = meanSquaredError(conus, truth, roi), uniformError = meanSquaredError(uniform, truth, roi);
    EXPECT_GT(conusError, 0.0);
    EXPECT_LT(conusError, 0.01);  // above 20 dB
    EXPECT_LT(conusError, uniformError);
}

// The floor goes on across the seams of the cube faces that see it (+z and -y meet where its
// points lie as far down as ahead, z = 1 at y = -1; -x and -y at x = -1). A ray that meets it
// within 0.01 of a seam, in the strip between a face's last texel centres and its edge, enters the
// next face just behind the floor: it hits there, in the CoNUS faces (larger texels at the +z
// face's edge, where the focus took them) and the uniform ones alike, rather than showing the sky.
TEST(Reflection, FloorAcrossAFaceSeamIsHitNotMissed) {
    const MeshScene mesh(test::rampedBoxAndFloor(glm::vec3(kBoxLo), glm::vec3(kBoxHi)));
    const auto [conusFaces, uniformFaces] = bakeBoth(mesh);
    for (const auto* faces : {&conusFaces, &uniformFaces}) {
        for (int i = 0; i < 41; ++i)
            for (int j = 0; j < 31; ++j) {
                const double across = -0.7 + 1.4 * i / 40.0, off = -0.01 + 0.02 * j / 30.0;
                for (const glm::dvec3 target : {glm::dvec3(across, -1.0, 1.0 + off), glm::dvec3(-1.0 - off, -1.0, across)}) {
                    const glm::dvec3 from(0.07, 0.25, 0.1);  // near the centre, above it
                    const auto hit = traceReflection(*faces, Ray{from, glm::normalize(target - from)});
                    ASSERT_TRUE(hit) << (faces == &conusFaces ? "CoNUS" : "uniform") << " to " << target.x << ", " << target.z;
                    // Near the target, on the floor or less than a jump (5% of the depth, about 1)
                    // behind it, where the ray entered the next face.
                    EXPECT_NEAR(hit->hit.position.y, -1.0, 0.06);
                    EXPECT_LT(glm::distance(hit->hit.position, target), 0.08);
                }
            }
    }
}

// Layered faces: an occluding box before a wall (test::boxBeforeWall), seen from the centre at
// the origin along +z; rays from points beside the centre (where a mirror of radius 1 reflects
// from) that pass behind the box's front surface.
using test::kOccluderHi;
using test::kOccluderLo;
using test::kWallHi;
using test::kWallLo;

const MeshScene& occluderAndWall() {
    static const MeshScene scene(test::boxBeforeWall());
    return scene;
}

std::vector<ReflectionFace> bakeLayers(int layers) {
    ReflectionBakeOptions o;
    o.size = 96;
    o.layers = layers;
    o.roi = AxisBox{kOccluderLo, kOccluderHi};
    return bakeReflection(occluderAndWall(), o);
}

struct LayerScore {
    int rays = 0, right = 0, hidden = 0;
};

// Rays from `from` to `targets` (each expected to meet the surface there first: `expected` gives
// the analytic t or nothing to skip the target); right: the traced hit within `tolerance` of it.
template <class Expected>
LayerScore score(const std::vector<ReflectionFace>& faces, glm::dvec3 from, const std::vector<glm::dvec3>& targets,
                 Expected expected, double tolerance) {
    LayerScore s;
    for (const glm::dvec3& target : targets) {
        const Ray ray{from, glm::normalize(target - from)};
        const std::optional<double> t = expected(ray);
        if (!t) continue;
        ++s.rays;
        const auto hit = traceReflection(faces, ray);
        if (!hit) continue;
        s.hidden += hit->hit.hidden;
        s.right += glm::distance(hit->hit.position, ray.origin + ray.direction * *t) < tolerance;
    }
    return s;
}

TEST(ReflectionLayers, ARayBehindTheOccluderMeetsTheWallBehindIt) {
    // Targets on the wall's front (z = 3) in the occluder's shadow from the centre, so a single
    // layer stores the box there, and the wall only in deeper layers (the box's back face is the
    // second surface, the wall the third).
    std::mt19937 random(7);
    std::uniform_real_distribution<double> inset(0.1, 0.9);
    std::vector<glm::dvec3> targets;
    for (int i = 0; i < 300; ++i) {
        const glm::dvec3 onFront(kOccluderLo.x + inset(random) * (kOccluderHi.x - kOccluderLo.x),
                                 kOccluderLo.y + inset(random) * (kOccluderHi.y - kOccluderLo.y), kOccluderLo.z);
        targets.push_back(onFront * (kWallLo.z / kOccluderLo.z));
    }
    for (const glm::dvec3 from : {glm::dvec3(0.9, 0.2, 0.3), glm::dvec3(-0.6, -0.7, 0.1)}) {
        const auto expected = [&](const Ray& ray) -> std::optional<double> {
            if (test::hitBox(ray, kOccluderLo, kOccluderHi)) return std::nullopt;  // the box still in the way
            const auto wall = test::hitBox(ray, kWallLo, kWallHi);
            if (!wall || wall->axis != 2) return std::nullopt;
            return wall->t;
        };
        const LayerScore one = score(bakeLayers(1), from, targets, expected, 0.03);
        const LayerScore three = score(bakeLayers(3), from, targets, expected, 0.03);
        ASSERT_GT(one.rays, 60) << "from " << from.x;
        // One layer knows nothing behind the box: its hits are guesses (hidden) or elsewhere.
        EXPECT_LT(one.right, one.rays / 4) << "from " << from.x;
        EXPECT_GT(one.hidden, one.rays / 2) << "from " << from.x;
        // Three meet the wall where the ray does.
        EXPECT_GE(three.right, three.rays - three.rays / 50) << "from " << from.x;
        EXPECT_EQ(three.hidden, 0) << "from " << from.x;
    }
}

TEST(ReflectionLayers, ARayMeetsTheOccludersSideThatFacesAwayFromTheCentre) {
    // The box's side x = hi.x faces away from the centre (its normal +x, the centre at x = 0 <
    // hi.x): the centre sees it only through the box, as the second surface along its rays; a
    // point to the right of the centre sees it from outside.
    std::mt19937 random(11);
    std::uniform_real_distribution<double> inset(0.1, 0.9);
    std::vector<glm::dvec3> targets;
    for (int i = 0; i < 300; ++i)
        targets.push_back({kOccluderHi.x, kOccluderLo.y + inset(random) * (kOccluderHi.y - kOccluderLo.y),
                           kOccluderLo.z + inset(random) * (kOccluderHi.z - kOccluderLo.z)});
    const glm::dvec3 from(1.0, -0.15, 0.2);
    const auto expected = [&](const Ray& ray) -> std::optional<double> {
        const auto box = test::hitBox(ray, kOccluderLo, kOccluderHi);
        if (!box || box->axis != 0) return std::nullopt;
        return box->t;
    };
    const LayerScore one = score(bakeLayers(1), from, targets, expected, 0.03);
    const LayerScore two = score(bakeLayers(2), from, targets, expected, 0.03);
    ASSERT_GT(one.rays, 200);
    EXPECT_LT(one.right, one.rays / 4);
    // The side is seen edge-on from the centre (about 2 degrees across, 8 texels of the focused
    // face): a few rays near its edges land more than 0.03 off (measured: 278 of 294 within).
    EXPECT_GE(two.right, two.rays * 9 / 10);
}

TEST(ReflectionLayers, OneLayerIsTheSingleLayerAssetAndLayersRoundTrip) {
    const std::vector<ReflectionFace> one = bakeLayers(1), three = bakeLayers(3);
    ASSERT_EQ(one.front().layers(), 1);
    ASSERT_EQ(three.front().layers(), 3);
    // Layer 0 of a layered bake is the single-layer bake, texel for texel.
    for (std::size_t f = 0; f < one.size(); ++f) {
        EXPECT_EQ(one[f].image.pixels, three[f].image.pixels);
        EXPECT_EQ(one[f].depth.depths(), three[f].depth.depths());
    }
    // Deeper layers lie behind: where layer k saw a surface, its depth exceeds layer k-1's.
    int behind = 0;
    for (const ReflectionFace& face : three)
        for (int k = 1; k < face.layers(); ++k)
            for (int y = 0; y < face.image.height; ++y)
                for (int x = 0; x < face.image.width; ++x)
                    if (face.layerImage(k).at(x, y, kMeshChannelA) > 0) {
                        ++behind;
                        EXPECT_GT(face.layerDepth(k).depthAt(x, y), face.layerDepth(k - 1).depthAt(x, y));
                    }
    EXPECT_GT(behind, 1000);
    // Through the file and back: the same layers, and a single-layer file stays single.
    const conus::test::TestDir dir("reflection-layers");
    const std::string path = dir.file("layered.exr");
    format::writeReflectionAsset(path, reflectionAssetFile(three));
    EXPECT_TRUE(format::validateConusFile(path).ok());
    const std::vector<ReflectionFace> read = readReflectionFaces(path);
    ASSERT_EQ(read.front().layers(), 3);
    for (std::size_t f = 0; f < read.size(); ++f)
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(read[f].layerDepth(k).depths(), three[f].layerDepth(k).depths());
            EXPECT_EQ(read[f].layerImage(k).pixels, three[f].layerImage(k).pixels);
        }
    format::writeReflectionAsset(path, reflectionAssetFile(one));
    EXPECT_EQ(readReflectionFaces(path).front().layers(), 1);
    EXPECT_TRUE(format::validateConusFile(path).ok());
}

TEST(ReflectionLayers, TheBakeCountsDisocclusionsAndAutoStopsWhenLayersCoverLittle) {
    const MeshScene& scene = occluderAndWall();
    // The wall seen past the box, and the box's sides, need deeper layers; beyond the third
    // (the wall) nothing is left that a mirror of radius 1 sees.
    const double one = disocclusionFraction(scene, {0, 0, 0}, 1.0, 1), three = disocclusionFraction(scene, {0, 0, 0}, 1.0, 3);
    EXPECT_GT(one, 0.0);
    EXPECT_LT(three, one / 5);
    EXPECT_EQ(disocclusionFraction(scene, {0, 0, 0}, 0.0, 1), 0.0);  // the centre sees all it meets
    // Auto keeps the layers up to the first that covers under 1% of the faces' texels, counted
    // here on the bake of every layer.
    ReflectionBakeOptions o;
    o.size = 32;
    o.layers = kMaxReflectionLayers;
    const auto all = bakeReflection(scene, o);
    int expected = 1;
    for (int k = 1; k < kMaxReflectionLayers; ++k) {
        double covered = 0, texels = 0;
        for (const ReflectionFace& face : all)
            for (std::size_t i = 0; i < face.layerDepth(k).depths().size(); ++i) {
                covered += face.layerImage(k).pixels[i * 5 + kMeshChannelA] > 0;
                texels += 1;
            }
        if (covered / texels < kLayerMinCoverage) break;
        expected = k + 1;
    }
    o.layers = 0;
    const auto faces = bakeReflection(scene, o);
    EXPECT_EQ(faces.front().layers(), expected);
    EXPECT_GE(expected, 2);  // the box's back and the wall's cover more than 1%
    EXPECT_LT(expected, kMaxReflectionLayers);
    o.layers = kMaxReflectionLayers + 1;
    EXPECT_THROW(bakeReflection(scene, o), Error);
}

}  // namespace
}  // namespace conus::codec
