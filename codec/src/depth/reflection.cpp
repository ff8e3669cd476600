#include "conus/codec/depth/reflection.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <string>

#include "conus/codec/conus_file.h"
#include "conus/codec/mesh/shading.h"
#include "conus/core/error.h"
#include "conus/core/fpc.h"
#include "conus/core/mesh.h"
#include "conus/core/parallel.h"

namespace conus::codec {
namespace {

bool finite(glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// A face's far plane lies where nothing was seen (coverage 0): a hit there, or one the bisection
// leaves just short of it, is the sky, not a surface. A hidden hit (intersect.h) lies on the
// background carried on behind an occluder, wherever the ray ends: its texel alone says.
bool onSky(const DepthHit& hit, const ReflectionFace& face, int layer) {
    return face.layerImage(layer).at(hit.texel.x, hit.texel.y, kMeshChannelA) < 0.5f ||
           (!hit.hidden && hit.depth >= face.depth.camera().far() * (1.0 - 1e-4));
}

// The Z channel of a mesh render.
std::vector<float> depthsOf(const Image& rgbaz) {
    std::vector<float> depths(static_cast<std::size_t>(rgbaz.width) * rgbaz.height);
    for (std::size_t i = 0; i < depths.size(); ++i) depths[i] = rgbaz.pixels[i * rgbaz.channels.size() + kMeshChannelZ];
    return depths;
}

// The fraction of the faces' texels that layer k covers.
double layerCoverage(const std::vector<ReflectionFace>& faces, int k) {
    double covered = 0, texels = 0;
    for (const ReflectionFace& face : faces) {
        const Image& image = face.layerImage(k);
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) covered += image.at(x, y, kMeshChannelA) > 0.0f ? 1.0 : 0.0;
        texels += double(image.width) * image.height;
    }
    return texels > 0 ? covered / texels : 0.0;
}

// The context a face's focus multiplies, from a uniform render of the face: a reflected ray meets
// the wrong surface mostly beside an outline against the sky (nothing is stored behind it), and the
// sky itself needs few texels. Texels within kOutlineBand of such an outline get kOutlineDensity,
// the sky beyond kSkyDensity, surfaces 1 (bench/notes/2026-11-27-reflection-rest.md: the band buys
// the rest of the mirror what the focus takes from it; the sky's saving alone does not).
constexpr int kOutlineBand = 4;          // texels of the face, either side of the outline
constexpr float kOutlineDensity = 6.0f;
constexpr float kSkyDensity = 0.5f;

// Running maximum of `values` over a window of kOutlineBand either side, along rows (step 1) or
// columns (step w); the window clamps at the border.
std::vector<std::uint8_t> windowMax(const std::vector<std::uint8_t>& values, int w, int h, bool columns) {
    std::vector<std::uint8_t> out(values.size());
    const int n = columns ? h : w, lines = columns ? w : h;
    for (int line = 0; line < lines; ++line)
        for (int i = 0; i < n; ++i) {
            std::uint8_t m = 0;
            for (int j = std::max(0, i - kOutlineBand); j <= std::min(n - 1, i + kOutlineBand); ++j)
                m = std::max(m, values[columns ? std::size_t(j) * w + line : std::size_t(line) * w + j]);
            out[columns ? std::size_t(i) * w + line : std::size_t(line) * w + i] = m;
        }
    return out;
}

// Nothing when the face sees no outline (all surface or all sky): the focus alone then.
std::optional<DensityField> outlineContext(const Image& uniform) {
    const int w = uniform.width, h = uniform.height;
    std::vector<std::uint8_t> seen(std::size_t(w) * h), unseen(seen.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            seen[std::size_t(y) * w + x] = uniform.at(x, y, kMeshChannelA) >= 0.5f;
            unseen[std::size_t(y) * w + x] = !seen[std::size_t(y) * w + x];
        }
    // A texel lies in the band when its (2 kOutlineBand + 1)^2 window holds both.
    const std::vector<std::uint8_t> anySeen = windowMax(windowMax(seen, w, h, false), w, h, true);
    const std::vector<std::uint8_t> anyUnseen = windowMax(windowMax(unseen, w, h, false), w, h, true);
    DensityField field{w, h, std::vector<float>(seen.size())};
    bool outline = false;
    for (std::size_t i = 0; i < seen.size(); ++i) {
        const bool band = anySeen[i] && anyUnseen[i];
        outline = outline || band;
        field.values[i] = band ? kOutlineDensity : seen[i] ? 1.0f : kSkyDensity;
    }
    if (!outline) return std::nullopt;
    return field;
}

// A baked texel's colour is the mean over kTexelRays^2 rays spread evenly over its footprint (the
// texel's square in the map's distorted image, each position undistorted), counting those that meet
// the surface its centre ray meets (covered, Z within kSameSurface of the centre's); its A and Z
// stay the centre ray's: one exact surface, never a mean across a silhouette. One ray a texel
// point-samples a texture many times finer than the texels (the milk truck's 2048^2 texture seen
// from 17 units away) and stores aliased values where the surface's mean belongs. kTexelRays is
// odd, so the middle ray is the centre ray.
constexpr int kTexelRays = 3;
constexpr double kSameSurface = 0.05;

void filterTexelColours(const MeshScene& scene, const Fpc& fpc, Image& rgbaz) {
    const int w = rgbaz.width, h = rgbaz.height;
    const Distortion* distortion = fpc.distortion();
    parallelRows(h, 0, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                if (rgbaz.at(x, y, kMeshChannelA) <= 0.0f) continue;
                const float z = rgbaz.at(x, y, kMeshChannelZ);
                glm::vec3 sum(0.0f);
                int n = 0;
                for (int j = 0; j < kTexelRays; ++j)
                    for (int i = 0; i < kTexelRays; ++i) {
                        const glm::dvec2 pd((x + (i + 0.5) / kTexelRays) / w, (y + (j + 0.5) / kTexelRays) / h);
                        const auto ray = shadeRay(scene, fpc.camera(), distortion ? distortion->undistort(pd) : pd);
                        if (!(ray[kMeshChannelA] > 0.0f) || std::abs(ray[kMeshChannelZ] - z) > kSameSurface * z) continue;
                        sum += glm::vec3(ray[0], ray[1], ray[2]);
                        ++n;
                    }
                if (n == 0) continue;  // the centre ray itself always counts; kept for safety
                for (int c = 0; c < 3; ++c) rgbaz.at(x, y, kMeshChannelR + c) = sum[c] / float(n);
            }
    }, 4);
}

// A plane mirror's in-plane axes for unit normal n: any orthonormal pair; the mirror is square
// about its centre, so a disc test would not do, but the pair's choice only turns the square in
// its plane.
void planeAxes(glm::dvec3 n, glm::dvec3& s, glm::dvec3& u) {
    const glm::dvec3 helper = std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    s = glm::normalize(glm::cross(helper, n));
    u = glm::cross(n, s);
}

}  // namespace

Camera cubeFaceCamera(glm::dvec3 centre, int face, double near, double far) {
    if (face < 0 || face >= kCubeFaces) throw Error(ErrorCode::InvalidArgument, "cube face " + std::to_string(face) + " is not 0..5");
    if (!finite(centre) || !(near > 0) || !(far > near) || !std::isfinite(far))
        throw Error(ErrorCode::InvalidArgument, "cube face camera: needs a finite centre and 0 < near < far");
    const auto& a = format::kCubeFaceAxes[static_cast<std::size_t>(face)];
    const glm::dvec3 forward(a[0], a[1], a[2]), up(a[3], a[4], a[5]);
    return Camera::perspective(centre, centre + forward, up, 90.0, 1.0, near, far);
}

std::optional<Focus> reflectionFocus(const Camera& face, const AxisBox& roi, double magnification) {
    glm::dvec2 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p(corner & 1 ? roi.hi.x : roi.lo.x, corner & 2 ? roi.hi.y : roi.lo.y,
                           corner & 4 ? roi.hi.z : roi.lo.z);
        const glm::dvec3 q = face.project(p);
        // A corner behind the eye: the box straddles the face's plane, so its projection is
        // unbounded; the face sees part of it at most obliquely, and a focus would be a guess.
        if (!(q.z > 0)) return std::nullopt;
        lo = glm::min(lo, glm::dvec2(q));
        hi = glm::max(hi, glm::dvec2(q));
    }
    lo = glm::clamp(lo, 0.0, 1.0);
    hi = glm::clamp(hi, 0.0, 1.0);
    if (!(hi.x > lo.x && hi.y > lo.y)) return std::nullopt;
    // The focus magnifies fully inside radius r and falls off to the context by 2r. Its disc is
    // the one inscribed in the bounding square of the clipped projection (r half its larger side;
    // faces are square, r a fraction of the width): the corners lie in the fall-off. The bounding
    // disc instead (r half the diagonal) spreads the texels over 2x the area and reached a lower
    // rate on the box, 1.8x against 2.2x at k = 3 (bench/notes/2026-11-24-reflections.md).
    const glm::dvec2 c = 0.5 * (lo + hi);
    const glm::dvec2 extent = hi - lo;
    const double r = std::clamp(0.5 * std::max(extent.x, extent.y), 0.02, 0.5);
    return Focus{std::clamp(c.x, 0.0, 1.0), std::clamp(c.y, 0.0, 1.0), r, magnification};
}

std::vector<ReflectionFace> bakeReflection(const MeshScene& scene, const ReflectionBakeOptions& o) {
    if (o.size < 8 || o.size > 4096) throw Error(ErrorCode::InvalidArgument, "reflection faces must be 8 to 4096 texels a side");
    if (!(o.magnification >= 1.0 && o.magnification <= 16.0))
        throw Error(ErrorCode::InvalidArgument, "reflection magnification must lie in [1, 16]");
    if (!finite(o.centre)) throw Error(ErrorCode::InvalidArgument, "the reflector's centre is not finite");
    if (o.layers < 0 || o.layers > kMaxReflectionLayers)
        throw Error(ErrorCode::InvalidArgument, "reflection layers must be 1 to " + std::to_string(kMaxReflectionLayers) +
                                                    " (0: as many as the scene needs), not " + std::to_string(o.layers));
    const int peel = o.layers == 0 ? kMaxReflectionLayers : o.layers;
    const AxisBox bounds = boundsOf(scene.mesh());
    // Far: beyond every point of the scene from the centre (the farthest box corner), with room.
    const glm::dvec3 reach = glm::max(glm::abs(bounds.lo - o.centre), glm::abs(bounds.hi - o.centre));
    const double far = 1.01 * glm::length(reach) + 1e-6;
    if (!(o.near > 0) || !(far > o.near))
        throw Error(ErrorCode::InvalidArgument, "the reflector's near clip must be positive and closer than the scene");
    const AxisBox roi = o.roi.value_or(bounds);

    std::vector<ReflectionFace> faces;
    faces.reserve(kCubeFaces);
    const std::shared_ptr<const SamplingMap> identity = std::make_shared<SamplingMap>(SamplingMap::identity(2, 2));
    for (int f = 0; f < kCubeFaces; ++f) {
        const Camera camera = cubeFaceCamera(o.centre, f, o.near, far);
        std::shared_ptr<const SamplingMap> map = identity;
        std::optional<Focus> focus;
        if (!o.uniform) focus = reflectionFocus(camera, roi, o.magnification);
        // A face without a focus keeps the identity: its context gives no texels to the focus, and
        // a map bent by the outline band alone moves straight outlines off its texel rows (the pole
        // of the bench's +x face: -1 dB, bench/notes/2026-11-27-reflection-rest.md).
        if (focus) {
            const std::optional<DensityField> context = outlineContext(renderMeshReference(scene, Fpc(camera, identity), o.size, o.size));
            FociOptions foci;
            foci.aspect = 1.0;
            foci.falloff = kFormatFalloff;  // the r..2r ring: the faces' figures were measured with it (a narrow one: -0.8 dB)
            foci.context = context ? &*context : nullptr;
            map = std::make_shared<SamplingMap>(buildFociMap(std::span<const Focus>(&*focus, 1), foci));
        }
        if (peel == 1) {
            Image rgbaz = renderMeshReference(scene, Fpc(camera, map), o.size, o.size);
            filterTexelColours(scene, Fpc(camera, map), rgbaz);
            faces.push_back({DepthImage(camera, map, o.size, o.size, depthsOf(rgbaz), false), std::move(rgbaz), {}});
            continue;
        }
        std::vector<Image> layers = renderMeshLayers(scene, Fpc(camera, map), o.size, o.size, peel);
        filterTexelColours(scene, Fpc(camera, map), layers[0]);
        ReflectionFace face{DepthImage(camera, map, o.size, o.size, depthsOf(layers[0]), false), std::move(layers[0]), {}};
        for (std::size_t k = 1; k < layers.size(); ++k)
            face.behind.push_back({DepthImage(camera, map, o.size, o.size, depthsOf(layers[k]), false), std::move(layers[k])});
        faces.push_back(std::move(face));
    }
    if (o.layers == 0) {  // as many as the scene needs: up to the first layer that covers too little
        int keep = 1;
        while (keep < peel && layerCoverage(faces, keep) >= kLayerMinCoverage) ++keep;
        for (ReflectionFace& face : faces) face.behind.erase(face.behind.begin() + (keep - 1), face.behind.end());
    }
    return faces;
}

std::optional<ReflectorHit> hitReflector(const Reflector& r, const Ray& ray) {
    const glm::dvec3 d = ray.direction;
    ReflectorHit out;
    if (r.kind == Reflector::Kind::Sphere) {
        const glm::dvec3 oc = ray.origin - r.centre;
        const double b = glm::dot(oc, d), c = glm::dot(oc, oc) - r.radius * r.radius;
        const double disc = b * b - c;
        if (!(disc >= 0)) return std::nullopt;
        const double t = -b - std::sqrt(disc);  // the outside of the sphere: the eye is outside
        if (!(t > 0)) return std::nullopt;
        out.t = t;
        out.normal = glm::normalize(ray.origin + d * t - r.centre);
    } else {
        const glm::dvec3 n = glm::normalize(r.normal);
        const double facing = glm::dot(d, n);
        if (!(facing < 0)) return std::nullopt;  // the mirror's back or edge-on
        const double t = glm::dot(r.centre - ray.origin, n) / facing;
        if (!(t > 0)) return std::nullopt;
        const glm::dvec3 p = ray.origin + d * t - r.centre;
        glm::dvec3 s, u;
        planeAxes(n, s, u);
        if (std::abs(glm::dot(p, s)) > r.radius || std::abs(glm::dot(p, u)) > r.radius) return std::nullopt;
        out.t = t;
        out.normal = n;
    }
    out.reflected.origin = ray.origin + d * out.t;
    out.reflected.direction = glm::normalize(d - 2.0 * glm::dot(d, out.normal) * out.normal);
    return out;
}

glm::vec3 reflectionColour(const ReflectionFace& face, const DepthHit& hit) { return reflectionColour(face, 0, hit); }

glm::vec3 reflectionColour(const ReflectionFace& face, int layer, const DepthHit& hit) {
    const Image& c = face.layerImage(layer);
    const auto texel = [&](glm::ivec2 t) {
        return glm::vec4(c.at(t.x, t.y, kMeshChannelR), c.at(t.x, t.y, kMeshChannelR + 1),
                         c.at(t.x, t.y, kMeshChannelR + 2), c.at(t.x, t.y, kMeshChannelA));
    };
    // The surface's own weights (a silhouette's far side weighs nothing), times coverage.
    const DepthImage::Weights weights = face.layerDepth(layer).surfaceWeights(hit.distorted);
    glm::vec3 sum(0.0f);
    float w = 0.0f;
    for (int k = 0; k < 4; ++k) {
        const glm::vec4 t = texel(weights.texel[k]);
        const float wk = static_cast<float>(weights.weight[k]) * t.a;
        sum += glm::vec3(t) * wk;
        w += wk;
    }
    if (!(w > 0.0f)) return glm::vec3(texel(hit.texel));
    return sum / w;
}

std::optional<ReflectionHit> traceReflection(const std::vector<ReflectionFace>& faces, const Ray& ray,
                                             const IntersectOptions& options) {
    std::optional<ReflectionHit> best;
    for (std::size_t f = 0; f < faces.size(); ++f) {
        const ReflectionFace& face = faces[f];
        IntersectOptions o = options;
        if (best) o.tMax = best->hit.t;
        double firstHidden = 0;
        const auto hit = intersect(face.depth, ray, o, firstHidden);
        std::optional<ReflectionHit> mine;
        // A hidden hit is a guess (the background carried on behind an occluder); a layered face
        // holds what lies behind its occluders, so that a ray that meets none of its layers there
        // meets nothing in this face: the guess is the single-layer face's alone.
        if (hit && !onSky(*hit, face, 0) && !(best && hit->t >= best->hit.t) && !(hit->hidden && face.layers() > 1))
            mine = ReflectionHit{*hit, static_cast<int>(f), 0, reflectionColour(face, 0, *hit)};
        // The deeper layers (intersect.h): only behind a silhouette, from where the ray first went
        // behind it, short of a layer-0 hit.
        if (firstHidden < o.tMax && face.layers() > 1) {
            const Ray behind{ray.origin + ray.direction * firstHidden, ray.direction};
            for (int k = 1; k < face.layers(); ++k) {
                IntersectOptions d = o;
                d.tMax = (mine ? mine->hit.t : o.tMax) - firstHidden;
                if (!(d.tMax > 0.0)) break;
                auto deeper = intersectBehind(face.layerDepth(k), behind, d);
                if (!deeper || onSky(*deeper, face, k)) continue;
                deeper->t += firstHidden;
                mine = ReflectionHit{*deeper, static_cast<int>(f), k, reflectionColour(face, k, *deeper)};
            }
        }
        if (mine) best = mine;
    }
    return best;
}

namespace {

// The channel a face's layer k stores `name` in (spec "Reflection assets": layer 0 the plain
// names, layer k >= 1 `layer<k>.<name>`).
std::string layerChannel(int k, const std::string& name) { return k == 0 ? name : "layer" + std::to_string(k) + "." + name; }

// Layer k's channels of a face file as a mesh render (R, G, B, A, Z in that order).
Image layerFromFile(const format::ConusFile& file, int k) {
    const std::vector<std::string> names = meshChannelNames();
    // The file keeps channels in its own (EXR: alphabetical) order; faces hold the mesh render's.
    Image image{file.image.width, file.image.height, names, std::vector<float>(std::size_t(file.image.width) * file.image.height * names.size())};
    for (std::size_t c = 0; c < names.size(); ++c) {
        const int from = file.image.channelIndex(layerChannel(k, names[c]));
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x)
                image.at(x, y, static_cast<int>(c)) = from < 0 ? 1.0f : file.image.at(x, y, from);
    }
    return image;
}

ReflectionFace faceFromFile(const format::ConusFile& file) {
    DepthImage depth = DepthImage::fromFile(file);
    ReflectionFace face{depth, layerFromFile(file, 0), {}};
    for (int k = 1; file.image.channelIndex(layerChannel(k, "Z")) >= 0; ++k) {
        Image image = layerFromFile(file, k);
        face.behind.push_back({DepthImage(depth.camera(), depth.sharedMap(), image.width, image.height, depthsOf(image), false),
                               std::move(image)});
    }
    return face;
}

// A face's layers as one image: layer 0's channels, then each deeper layer's under its names.
Image layeredImage(const ReflectionFace& face) {
    if (face.behind.empty()) return face.image;
    const std::vector<std::string> names = meshChannelNames();
    Image out{face.image.width, face.image.height, {}, {}};
    for (int k = 0; k < face.layers(); ++k)
        for (const std::string& name : names) out.channels.push_back(layerChannel(k, name));
    out.pixels.resize(std::size_t(out.width) * out.height * out.channels.size());
    for (int k = 0; k < face.layers(); ++k) {
        const Image& layer = face.layerImage(k);
        for (int y = 0; y < out.height; ++y)
            for (int x = 0; x < out.width; ++x)
                for (std::size_t c = 0; c < names.size(); ++c)
                    out.at(x, y, static_cast<int>(k * names.size() + c)) = layer.at(x, y, static_cast<int>(c));
    }
    return out;
}

}  // namespace

format::ReflectionAssetFile reflectionAssetFile(const std::vector<ReflectionFace>& faces) {
    if (faces.size() != static_cast<std::size_t>(kCubeFaces))
        throw Error(ErrorCode::InvalidArgument, "a reflection asset has six faces, not " + std::to_string(faces.size()));
    format::ReflectionAssetFile asset;
    const glm::dvec3 centre = faces.front().depth.camera().eye();
    // + 0 turns the -0 an inverted matrix gives into 0 (the file and `conus info` show it).
    asset.frame.centre = {static_cast<float>(centre.x) + 0.0f, static_cast<float>(centre.y) + 0.0f, static_cast<float>(centre.z) + 0.0f};
    for (std::size_t f = 0; f < faces.size(); ++f) {
        if (faces[f].layers() != faces.front().layers())
            throw Error(ErrorCode::InvalidArgument, "every face of a reflection asset has one count of layers");
        asset.faces[f] = makeDepthImageFile(layeredImage(faces[f]), faces[f].depth.map(), faces[f].depth.camera(), "world");
    }
    return asset;
}

std::vector<ReflectionFace> reflectionFaces(const format::ReflectionAssetFile& asset) {
    std::vector<ReflectionFace> faces;
    for (const format::ConusFile& file : asset.faces) faces.push_back(faceFromFile(file));
    return faces;
}

std::vector<ReflectionFace> readReflectionFaces(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw Error(ErrorCode::Unsupported, path + " is a folder, not a reflection asset: an asset is one .exr file "
                                                   "(`conus bake reflection SCENE -o asset.exr` bakes one)");
    return reflectionFaces(format::readReflectionAsset(path));
}

std::optional<glm::vec3> traceReflectionReference(const MeshScene& scene, const Ray& ray, glm::dvec3 centre) {
    const auto hit = scene.intersect(ray, 1e-6);
    if (!hit) return std::nullopt;
    const glm::vec3 albedo = meshAlbedo(scene.mesh(), hit->triangle, hit->b1, hit->b2);
    const glm::dvec3 toCentre = centre - hit->position;
    const double length = glm::length(toCentre);
    const glm::vec3 l = length > 0 ? glm::vec3(toCentre / length) : hit->normal;
    return shadeHeadlight(albedo, hit->normal, l);
}

namespace {

glm::dvec3 unitVector(std::mt19937& random, std::normal_distribution<double>& gauss) {
    for (;;) {
        const glm::dvec3 v(gauss(random), gauss(random), gauss(random));
        if (const double l = glm::length(v); l > 1e-9) return v / l;
    }
}

// Whether the surface at `position` is among the first `layers` along the eye's ray to it: peeled
// from the eye toward it as the bake peels (shadeRayLayers' rule), until its own surface.
bool storedFrom(const MeshScene& scene, glm::dvec3 eye, glm::dvec3 position, int layers) {
    const glm::dvec3 toHit = position - eye;
    const double distance = glm::length(toHit);
    if (!(distance > 0)) return true;
    const Ray fromEye{eye, toHit / distance};
    double from = 1e-6;
    for (int k = 0; k < layers; ++k) {
        const auto on = scene.intersect(fromEye, from);
        if (!on) return false;
        if (on->distance >= distance * (1.0 - kPeelGap)) return true;
        from = on->distance * (1.0 + kPeelGap);
    }
    return false;
}

}  // namespace

double disocclusionFraction(const MeshScene& scene, glm::dvec3 centre, double radius, int layers, int rays, unsigned seed) {
    if (!(radius >= 0) || !std::isfinite(radius) || layers < 1 || rays < 1)
        throw Error(ErrorCode::InvalidArgument, "disocclusion: needs a radius >= 0, at least one layer and one ray");
    std::mt19937 random(seed);
    std::normal_distribution<double> gauss;
    std::vector<Ray> sample;
    sample.reserve(static_cast<std::size_t>(rays));
    for (int i = 0; i < rays; ++i) {
        const glm::dvec3 n = unitVector(random, gauss);
        glm::dvec3 d = unitVector(random, gauss);
        if (glm::dot(d, n) < 0) d = -d;
        sample.push_back(Ray{centre + n * radius, d});
    }
    return disocclusionFraction(scene, centre, sample, layers);
}

double disocclusionFraction(const MeshScene& scene, glm::dvec3 eye, const std::vector<Ray>& rays, int layers) {
    if (layers < 1 || !finite(eye)) throw Error(ErrorCode::InvalidArgument, "disocclusion: needs a finite eye and at least one layer");
    std::vector<int> met(rays.size()), unseen(rays.size());
    parallelRows(static_cast<int>(rays.size()), 0, [&](int i0, int i1) {
        for (int i = i0; i < i1; ++i) {
            const auto hit = scene.intersect(rays[static_cast<std::size_t>(i)], 1e-6);
            if (!hit) continue;
            met[static_cast<std::size_t>(i)] = 1;
            unseen[static_cast<std::size_t>(i)] = storedFrom(scene, eye, hit->position, layers) ? 0 : 1;
        }
    });
    const double hits = std::accumulate(met.begin(), met.end(), 0.0);
    return hits > 0 ? std::accumulate(unseen.begin(), unseen.end(), 0.0) / hits : 0.0;
}

std::vector<Ray> reflectedRays(const Reflector& r, glm::dvec3 viewpoint, int count, unsigned seed) {
    if (count < 1 || !finite(viewpoint)) throw Error(ErrorCode::InvalidArgument, "reflected rays: needs a finite viewpoint and a count >= 1");
    const bool plane = r.kind == Reflector::Kind::Plane;
    const glm::dvec3 n = glm::normalize(r.normal);
    if (plane ? !(glm::dot(viewpoint - r.centre, n) > 0) : !(glm::distance(viewpoint, r.centre) > r.radius))
        throw Error(ErrorCode::InvalidArgument, std::string("the viewpoint sees no mirror side: it is ") +
                                                    (plane ? "behind the plane mirror" : "inside the sphere"));
    std::mt19937 random(seed);
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> across(-1.0, 1.0);
    glm::dvec3 s, u;
    planeAxes(n, s, u);
    std::vector<Ray> rays;
    rays.reserve(static_cast<std::size_t>(count));
    while (static_cast<int>(rays.size()) < count) {
        // A point of the mirror side that faces the viewpoint, uniform over its area.
        glm::dvec3 p;
        if (plane) {
            p = r.centre + r.radius * (across(random) * s + across(random) * u);
        } else {
            p = r.centre + r.radius * unitVector(random, gauss);
            if (!(glm::dot(p - r.centre, viewpoint - p) > 0)) continue;  // the far side of the sphere
        }
        const Ray eye{viewpoint, glm::normalize(p - viewpoint)};
        if (const auto hit = hitReflector(r, eye)) rays.push_back(hit->reflected);
    }
    return rays;
}

glm::dvec3 reflectedViewpoint(const Reflector& r, glm::dvec3 viewpoint) {
    const glm::dvec3 n = glm::normalize(r.normal);
    if (r.kind == Reflector::Kind::Plane) return viewpoint - 2.0 * glm::dot(viewpoint - r.centre, n) * n;
    // A convex mirror of focal length r/2: an object d - r before its surface has its virtual
    // image 1 / (2/r + 1/(d - r)) behind it.
    const glm::dvec3 toView = viewpoint - r.centre;
    const double d = glm::length(toView);
    if (!(d > r.radius)) return r.centre;
    return r.centre + toView / d * (r.radius - 1.0 / (2.0 / r.radius + 1.0 / (d - r.radius)));
}

EyePlacement placeReflectionEye(const MeshScene& scene, const Reflector& reflector, glm::dvec3 viewpoint, int layers, int rays) {
    if (layers < 0 || layers > kMaxReflectionLayers)
        throw Error(ErrorCode::InvalidArgument, "eye placement: layers must be 0 to " + std::to_string(kMaxReflectionLayers));
    const std::vector<Ray> sample = reflectedRays(reflector, viewpoint, rays);
    const glm::dvec3 image = reflectedViewpoint(reflector, viewpoint);
    glm::dvec3 eyes[kEyeCandidates];
    double fractions[kEyeCandidates];
    for (int k = 0; k < kEyeCandidates; ++k) {
        eyes[k] = reflector.centre + (image - reflector.centre) * (double(k) / (kEyeCandidates - 1));
        fractions[k] = disocclusionFraction(scene, eyes[k], sample, std::max(layers, 1));
    }
    const double fewest = *std::min_element(fractions, fractions + kEyeCandidates);
    int k = 0;
    while (fractions[k] > fewest + kEyeTie) ++k;
    EyePlacement placed{eyes[k], fractions[k], fractions[0], std::max(layers, 1)};
    if (layers == 0)
        for (double f = fractions[k]; f >= kLayerMinCoverage && placed.layers < kMaxReflectionLayers;)
            f = disocclusionFraction(scene, placed.eye, sample, ++placed.layers);
    return placed;
}

Image renderReflectionFrame(const MeshScene& scene, const std::vector<ReflectionFace>* faces, glm::dvec3 centre,
                            const Camera& camera, int width, int height, const ReflectionFrameOptions& o) {
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw Error(ErrorCode::InvalidArgument, "reflection frames are 1 to 16384 pixels a side");
    if (o.samples < 1 || o.samples > kMaxFrameSamples)
        throw Error(ErrorCode::InvalidArgument, "reflection frames take 1 to " + std::to_string(kMaxFrameSamples) +
                                                    " rays a pixel a side, not " + std::to_string(o.samples));
    checkIntersectOptions(o.intersect);
    // Each pixel traces its eye ray against the mesh and, without faces, the ray the mirror
    // reflects there: probed first as the mesh render probes its rays (checkSurfaceOverlap).
    {
        const int columns = std::clamp(width, 1, 64), rows = std::clamp(height, 1, 64);
        std::vector<RaySpan> spans;
        spans.reserve(std::size_t(columns) * std::size_t(rows) * (faces ? 1 : 2));
        for (int j = 0; j < rows; ++j)
            for (int i = 0; i < columns; ++i) {
                const Ray ray = camera.ray({(i + 0.5) / columns, (j + 0.5) / rows});
                const double cosine = glm::dot(ray.direction, camera.forward());
                if (cosine > 0) spans.push_back({ray, camera.near() / cosine, camera.far() / cosine});
                if (const auto mirror = hitReflector(o.reflector, ray); mirror && !faces) spans.push_back({mirror->reflected, 1e-6});
            }
        checkSurfaceOverlap(scene, spans, "reflection frame");
    }
    // One ray: its colour and the mask M.
    const auto shade = [&](glm::dvec2 uv, glm::vec3& colour) {
        const Ray ray = camera.ray(uv);
        const std::array<float, 5> behind = shadeRay(scene, camera, uv);
        colour = glm::vec3(behind[0], behind[1], behind[2]);
        const auto mirror = hitReflector(o.reflector, ray);
        if (!mirror) return 0.0f;
        const double depth = camera.project(ray.origin + ray.direction * mirror->t).z;
        if (behind[kMeshChannelA] > 0 && depth >= behind[kMeshChannelZ]) return 0.0f;
        std::optional<glm::vec3> seen;
        if (faces) {
            if (const auto hit = traceReflection(*faces, mirror->reflected, o.intersect)) seen = hit->colour;
        } else {
            seen = traceReflectionReference(scene, mirror->reflected, centre);
        }
        colour = seen ? *seen : glm::vec3(kReflectionSky[0], kReflectionSky[1], kReflectionSky[2]);
        return seen ? 2.0f : 1.0f;
    };
    const int n = o.samples;
    Image frame{width, height, {"R", "G", "B", "M"}, std::vector<float>(static_cast<std::size_t>(width) * height * 4)};
    parallelRows(height, o.threads, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < width; ++x) {
            glm::vec3 sum(0.0f);
            float mask = 0;
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    glm::vec3 colour;
                    const float m = shade({(x + (i + 0.5) / n) / width, (y + (j + 0.5) / n) / height}, colour);
                    sum += colour;
                    if (i == n / 2 && j == n / 2) mask = m;
                }
            for (int c = 0; c < 3; ++c) frame.at(x, y, c) = sum[c] / float(n * n);
            frame.at(x, y, 3) = mask;
        }
    });
    return frame;
}

}  // namespace conus::codec
