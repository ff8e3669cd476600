// Reflection assets (paper section 5, Figure 6): the scene around a specular reflector stored as
// perspective CoNUS colour + depth images taken from the reflector's centre, and the reflected
// rays that intersect them (intersect.h, the one algorithm for any depth image).
//
// The asset is a cube of six faces (90 degree square frusta from the centre): six faces cover
// every direction a sphere reflects with no face wider than 90 degrees, where a perspective
// image's texels stay within a factor 3^(3/2) of each other in solid angle; fewer, wider faces
// would spend their texels unevenly before any map does. Each face is an ordinary CoNUS depth
// image (camera, map, Z = camera depth, the far plane where nothing was seen); the asset is one
// file of the six with the cube's frame (format/reflection_asset.h).
//
// The faces' maps favour what the reflector shows most: a focus on the projection of a region of
// interest (by default the scene's bounding box; in practice the object nearest the reflector) in
// every face that sees it, over a context that gives the face's outlines against the sky more
// texels and the sky fewer (what a uniform render of the face sees); the other faces keep the
// identity. The uniform baseline has the identity map and the same texel count.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/builders/foci.h"
#include "conus/codec/depth/intersect.h"
#include "conus/codec/mesh/raycast.h"
#include "conus/core/bounds.h"
#include "conus/core/enum_names.h"
#include "conus/core/image.h"
#include "conus/format/reflection_asset.h"

namespace conus::codec {

// The faces, in order, as the asset file names them (+x, -x, +y, -y, +z, -z).
inline constexpr int kCubeFaces = format::kCubeFaceCount;
using format::kCubeFaceNames;

// The camera of cube face `face` (0..5: +x, -x, +y, -y, +z, -z) at `centre`, the world's axes as
// the cube's (format::kCubeFaceAxes): 90 degrees, square, depths in [near, far]. Throws
// conus::Error(InvalidArgument) for a face outside 0..5 or bad clips.
Camera cubeFaceCamera(glm::dvec3 centre, int face, double near, double far);

// One surface layer of a face: its depth image (what rays intersect) and the mesh render it came
// from (R, G, B, A, Z per CoNUS pixel, codec/mesh/shading.h's channels; the colour a hit takes).
struct ReflectionLayer {
    DepthImage depth;
    Image image;
};

// One face: its first surface (`depth`, `image`: the single-layer asset) and the surfaces behind
// it along the face's rays, layer 1 on (depth peeling, intersect.h's layered images), each with
// the face's camera and map; none in a single-layer asset.
struct ReflectionFace {
    DepthImage depth;
    Image image;
    std::vector<ReflectionLayer> behind;

    int layers() const { return 1 + static_cast<int>(behind.size()); }
    const DepthImage& layerDepth(int k) const { return k == 0 ? depth : behind[static_cast<std::size_t>(k - 1)].depth; }
    const Image& layerImage(int k) const { return k == 0 ? image : behind[static_cast<std::size_t>(k - 1)].image; }
};

// The most layers a face keeps, and the coverage below which the bake adds no further layer when
// asked for as many as the scene needs: a layer found in under this fraction of the faces' texels
// buys less than it costs (every layer stores all its texels).
inline constexpr int kMaxReflectionLayers = 4;
inline constexpr double kLayerMinCoverage = 0.01;

// The six faces as one asset file's contents (each face codec/conus_file.h's makeDepthImageFile,
// units "world"; the frame the first face's eye and the world's axes), and back. Throws
// conus::Error(InvalidArgument) for other than six faces.
format::ReflectionAssetFile reflectionAssetFile(const std::vector<ReflectionFace>& faces);
std::vector<ReflectionFace> reflectionFaces(const format::ReflectionAssetFile& asset);
// The faces of the asset file at `path` (format::readReflectionAsset). A folder (of face files,
// say) is refused with conus::Error(Unsupported) saying how to bake the one file.
std::vector<ReflectionFace> readReflectionFaces(const std::string& path);

using conus::AxisBox;  // core/bounds.h

struct ReflectionBakeOptions {
    glm::dvec3 centre{0.0};      // the reflector's centre (the faces' common eye)
    int size = 128;              // texels a face side
    bool uniform = false;        // identity maps: the conventional baseline of the same texel count
    double magnification = 4.0;  // linear magnification of the focus on the region of interest
    std::optional<AxisBox> roi;  // the region of interest; none: the scene's bounding box
    double near = 0.01;          // the faces' near clip (far: beyond the scene's bounding box)
    // Surfaces kept along each texel's ray: 1 (the first only) .. kMaxReflectionLayers, or 0: as
    // many as the scene needs (layers added while the next covers kLayerMinCoverage of the texels).
    int layers = 1;
};

// The focus a face puts on the region of interest: the disc inscribed in the bounding square of
// the box's projection clipped to the image (its corners in the focus's fall-off); nothing when
// the box is not in front of the face or misses its image.
std::optional<Focus> reflectionFocus(const Camera& face, const AxisBox& roi, double magnification);

// The six faces of `scene` from options.centre, each rendered by the Embree reference (one exact
// ray per CoNUS pixel for depth and coverage: depths of one surface, never a mean across a
// silhouette; the first layer's colour the mean of those of 3x3 rays over the texel that meet a
// surface within 5% of the centre ray's depth, so that a texture finer than the texels is not aliased); a face with a
// focus is rendered uniform first, for its context. Throws
// conus::Error(InvalidArgument) for a size outside [8, 4096], a magnification outside [1, 16],
// layers outside [0, kMaxReflectionLayers], a non-finite centre, or a centre inside no free space
// (a near clip at or beyond the far one). Deeper layers are rendered the same way
// (shadeRayLayers: the k-th surface along each CoNUS pixel's ray), through the layer-0 maps.
std::vector<ReflectionFace> bakeReflection(const MeshScene& scene, const ReflectionBakeOptions& options);

// A specular reflector: a sphere (centre, radius) or a square plane mirror (centre, unit normal,
// half the side, its in-plane axes from `up`).
struct Reflector {
    enum class Kind { Sphere, Plane } kind = Kind::Sphere;
    glm::dvec3 centre{0.0};
    double radius = 1.0;              // sphere radius, or half the plane mirror's side
    glm::dvec3 normal{0.0, 0.0, 1.0};  // plane: the mirror's face
};

struct ReflectorHit {
    double t = 0;          // along the eye ray
    glm::dvec3 normal{0.0};  // unit, facing the eye
    Ray reflected;         // from the hit point, direction d - 2 (d.n) n
};

// Where the eye ray meets the reflector's mirror side, and the reflected ray; nothing on a miss.
std::optional<ReflectorHit> hitReflector(const Reflector& reflector, const Ray& ray);

// The colour a hit on `face` takes: the face's CoNUS image at the hit's distorted position with
// the surface's own weights (DepthImage::surfaceWeights: bilinear, the far side of a silhouette
// weighing nothing) times coverage (the far plane's texels carry no colour); the hit's own texel
// where none of the four weighs anything.
glm::vec3 reflectionColour(const ReflectionFace& face, const DepthHit& hit);
// The same on layer `layer` of the face.
glm::vec3 reflectionColour(const ReflectionFace& face, int layer, const DepthHit& hit);

struct ReflectionHit {
    DepthHit hit;
    int face = 0;
    int layer = 0;           // the face's layer it lies on
    glm::vec3 colour{0.0f};  // reflectionColour
};

// The nearest hit of `ray` among the faces (each face intersected by intersect.h, its deeper
// layers as a layered image's: intersectBehind when layer 0's walk went hidden; the nearest t
// wins), or nothing when it meets only the far planes.
std::optional<ReflectionHit> traceReflection(const std::vector<ReflectionFace>& faces, const Ray& ray,
                                             const IntersectOptions& options = {});

// The ground truth of a reflected ray: the mesh itself traced (Embree), the hit shaded as the
// faces are (the headlight from `centre`, the faces' eye), so that only where the ray lands differs.
std::optional<glm::vec3> traceReflectionReference(const MeshScene& scene, const Ray& ray, glm::dvec3 centre);

// Mirror rays that land in a disocclusion: of `rays` rays leaving a sphere of `radius` about the
// centre (origins uniform on it, directions uniform over the outward hemisphere: what a sphere
// mirror of that radius reflects, a plane mirror's among them) that meet the scene, the fraction
// whose first surface (traced against the mesh) is not among the first `layers` surfaces along the
// centre's ray to it (shadeRayLayers' peeling rule): what no asset of that many layers stores.
double disocclusionFraction(const MeshScene& scene, glm::dvec3 centre, double radius, int layers, int rays = 20000,
                            unsigned seed = 1);

// The same for the rays of `rays` (unit directions) from an asset whose faces' eye is `eye`.
double disocclusionFraction(const MeshScene& scene, glm::dvec3 eye, const std::vector<Ray>& rays, int layers);

// What the reflector sends back toward `viewpoint`: `count` eye rays from the viewpoint to points
// uniform on the reflector's side that faces it (a plane mirror's square, a sphere's visible cap),
// each reflected there (hitReflector's ray). Throws conus::Error(InvalidArgument) for a count
// under 1, a non-finite viewpoint, or one that sees no mirror side (behind a plane, inside a sphere).
std::vector<Ray> reflectedRays(const Reflector& reflector, glm::dvec3 viewpoint, int count, unsigned seed = 1);

// Where the reflected viewpoint lies: a plane's mirror image of the viewpoint (every ray the
// mirror reflects toward the viewpoint passes through it, so an eye there stores the first surface
// along each of them); a sphere's paraxial virtual image of it, between the centre and the surface
// (its rays pass near it, no longer through one point).
glm::dvec3 reflectedViewpoint(const Reflector& reflector, glm::dvec3 viewpoint);

// The faces' eye placed for a reflector seen from about `viewpoint`: of the candidates on the
// segment from the reflector's centre to the reflected viewpoint (kEyeCandidates, evenly spaced,
// both ends included), the one where the fewest of reflectedRays land in a disocclusion of a
// `layers`-layer asset (0: as many as the view needs, placed for one); within kEyeTie of the
// fewest, the one nearest the centre (nearer the scene: more texels on it). Throws as reflectedRays.
inline constexpr int kEyeCandidates = 5;
inline constexpr double kEyeTie = 0.002;
// The rays a placement traces: a sphere's cap sends most of them past a small model, so the
// fraction of those that meet it rests on a few hundred at 4000 (the truck's sphere: the eye
// chosen moved between two samples).
inline constexpr int kViewRays = 16000;
struct EyePlacement {
    glm::dvec3 eye{0.0};
    double disoccluded = 0;        // at the eye, with the layers placed for
    double centreDisoccluded = 0;  // at the reflector's centre, for comparison
    // The layers the view needs at the eye: `layers` when given; for 0, the fewest (1 to
    // kMaxReflectionLayers) that leave under kLayerMinCoverage of the view's rays in a
    // disocclusion (what the view needs, where the bake's auto counts the faces' texels).
    int layers = 1;
};
EyePlacement placeReflectionEye(const MeshScene& scene, const Reflector& reflector, glm::dvec3 viewpoint, int layers,
                                int rays = kViewRays);

// What the reflector shows where a reflected ray meets nothing: a constant sky.
inline constexpr float kReflectionSky[3] = {0.55f, 0.65f, 0.8f};

// The most rays a frame pixel a side (samples x samples rays a pixel).
inline constexpr int kMaxFrameSamples = 16;

struct ReflectionFrameOptions {
    Reflector reflector;
    IntersectOptions intersect;
    int threads = 0;  // 0: all cores
    // samples x samples rays a pixel, one at the centre of each cell of a regular samples x samples
    // grid over the pixel, their colours box-filtered (averaged); 1: one ray through the pixel's
    // centre. 1 to kMaxFrameSamples.
    int samples = 1;
};

// The CPU reference of `render reflection`, width x height: each pixel's rays from `camera`; where
// one meets the reflector before the scene, the reflected ray's colour from `faces` (null: traced
// against the mesh, traceReflectionReference, the ground truth); elsewhere the scene as the mesh
// reference shades it (identity map). R, G, B are the mean over the pixel's rays. M, of the pixel's
// ray nearest its centre (the centre itself for an odd `samples`): 0 scene or nothing, 1 the
// reflector showing the sky, 2 the reflector showing the scene.
// Throws LimitExceeded, as checkSurfaceOverlap (raycast.h) does, when a probe of the rays it
// would trace against the mesh (eye rays, and reflected rays without faces) crosses too many
// surfaces on average.
Image renderReflectionFrame(const MeshScene& scene, const std::vector<ReflectionFace>* faces, glm::dvec3 centre,
                            const Camera& camera, int width, int height, const ReflectionFrameOptions& options);

constexpr auto enumNameTable(Reflector::Kind) {
    return makeEnumNameTable<Reflector::Kind>(
        "reflector", {{Reflector::Kind::Sphere, "sphere"}, {Reflector::Kind::Plane, "plane"}});
}

}  // namespace conus::codec
