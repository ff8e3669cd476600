// A reflection asset's rules (spec/conus-format.md, V18 and V19) on its faces' header models,
// each face first checked as a file of its own; and the in-memory asset's headers and validator.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "conus/core/camera.h"
#include "header_model_pvt.h"

namespace conus::format {
namespace detail {
namespace {

// Directions and positions agree to this, relative to the cube's size in world units: the frame
// and the cameras are stored as float.
constexpr double kTolerance = 1e-4;

std::string faceName(int f) { return kCubeFaceNames[f]; }

std::string vectorText(glm::dvec3 v) {
    v += 0.0;  // -0 reads as 0
    return "(" + numberText(v.x, 6) + ", " + numberText(v.y, 6) + ", " + numberText(v.z, 6) + ")";
}

// V18's layers: the deeper layers' channels (`layer<k>.R` .. `.Z`, k = 1..L-1) in one face; L, or
// 0 after saying what is wrong.
constexpr int kMaxLayers = 4;  // the spec's bound (Layers), which the writer and the GL renderer's side-by-side textures keep

int faceLayers(const PartModel& part, const std::string& face, ValidationReport& r) {
    int layers = 1;
    bool ok = true;
    for (const ChannelModel& c : part.channels) {
        if (c.name.rfind("layer", 0) != 0) continue;
        const std::size_t dot = c.name.find('.');
        const std::string number = c.name.substr(5, dot == std::string::npos ? std::string::npos : dot - 5);
        if (dot == std::string::npos || number.empty() || number.size() > 2 || number[0] == '0' ||
            !std::all_of(number.begin(), number.end(), [](char d) { return d >= '0' && d <= '9'; })) {
            r.add(Rule::V18, "face " + face + " has channel " + c.name + ", not a layer's (layer<k>.R, .G, .B, .A, .Z)");
            ok = false;
            continue;
        }
        const std::string suffix = c.name.substr(dot);
        if (suffix != ".R" && suffix != ".G" && suffix != ".B" && suffix != ".A" && suffix != ".Z") {
            r.add(Rule::V18, "face " + face + " has channel " + c.name + ", not a layer's (layer<k>.R, .G, .B, .A, .Z)");
            ok = false;
            continue;
        }
        if (std::stoi(number) >= kMaxLayers) {
            r.add(Rule::V18, "face " + face + " has channel " + c.name + ": an asset holds at most " + std::to_string(kMaxLayers) + " layers");
            ok = false;
            continue;
        }
        layers = std::max(layers, std::stoi(number) + 1);
        if (c.name.substr(dot) == ".Z" && c.type != ChannelType::Float) {
            r.add(Rule::V18, "face " + face + " channel " + c.name + " is not FLOAT");
            ok = false;
        }
    }
    for (int k = 1; k < layers; ++k)
        for (const char* channel : {".A", ".B", ".G", ".R", ".Z"}) {
            const std::string name = "layer" + std::to_string(k) + channel;
            if (std::none_of(part.channels.begin(), part.channels.end(), [&](const ChannelModel& c) { return c.name == name; })) {
                r.add(Rule::V18, "face " + face + " has no channel " + name + " (a layer holds R, G, B, A and Z; layers 1.." +
                                     std::to_string(layers - 1) + " all)");
                ok = false;
            }
        }
    return ok ? layers : 0;
}

// V18: what each face holds; the faces square and of one size.
void checkFaces(const AssetModel& faces, ValidationReport& r) {
    int layers = -1;
    const PartModel& first = faces[0].part(PartKind::Conus);
    for (int f = 0; f < kCubeFaceCount; ++f) {
        const HeaderModel& m = faces[static_cast<std::size_t>(f)];
        const PartModel& part = m.part(PartKind::Conus);
        if (m.dataKind.ok() && m.dataKind.value != enumName(DataKind::DepthImage))
            r.add(Rule::V18, "face " + faceName(f) + " has data kind " + m.dataKind.value + ", not " + enumName(DataKind::DepthImage));
        std::string missing;
        for (const char* channel : {"A", "B", "G", "R", "Z"})
            if (std::none_of(part.channels.begin(), part.channels.end(), [&](const ChannelModel& c) { return c.name == channel; }))
                missing += std::string(missing.empty() ? "" : ", ") + channel;
        if (!missing.empty()) r.add(Rule::V18, "face " + faceName(f) + " has no channel " + missing + " (a face holds R, G, B, A and Z)");
        if (const int l = faceLayers(part, faceName(f), r); l > 0) {
            if (layers > 0 && l != layers)
                r.add(Rule::V18, "face " + faceName(f) + " has " + std::to_string(l) + " layers, face " + faceName(0) + " " +
                                     std::to_string(layers) + "; every face has one count of layers");
            if (layers < 0) layers = l;
        }
        const std::int64_t w = part.dataWindow.width(), h = part.dataWindow.height();
        if (w != h) r.add(Rule::V18, "face " + faceName(f) + " is " + std::to_string(w) + "x" + std::to_string(h) + ", not square");
        else if (f > 0 && !(part.dataWindow == first.dataWindow))
            r.add(Rule::V18, "face " + faceName(f) + " is " + std::to_string(w) + "x" + std::to_string(h) + ", face " + faceName(0) +
                                 " " + std::to_string(first.dataWindow.width()) + "x" + std::to_string(first.dataWindow.height()) +
                                 "; every face has one size");
    }
}

// Present with its type, or said to be missing or mistyped.
template <class T>
bool present(const HeaderModel& m, const Attr<T>& a, const char* name, const char* type, ValidationReport& r) {
    const std::string where = " on part `" + m.partName(PartKind::Conus) + "` (the cube's frame)";
    if (!a.present) r.add(Rule::V19, std::string("missing attribute ") + name + " (" + type + ")" + where);
    else if (!a.typeOk) r.add(Rule::V19, std::string("attribute ") + name + " has type " + a.typeName + ", expected " + type + where);
    return a.ok();
}

// V19's first half: the frame itself. Returns its axes' rows when they are a rotation.
bool checkFrame(const HeaderModel& m, glm::dvec3& centre, glm::dmat3& axes, ValidationReport& r) {
    const bool haveCentre = present(m, m.cubeCentre, kAttrCubeCentre, specOf(&HeaderModel::cubeCentre).typeName(), r);
    const bool haveAxes = present(m, m.cubeAxes, kAttrCubeAxes, specOf(&HeaderModel::cubeAxes).typeName(), r);
    if (!haveCentre || !haveAxes) return false;
    const auto& c = m.cubeCentre.value;
    const auto& a = m.cubeAxes.value;
    const bool finite = std::all_of(c.begin(), c.end(), [](float x) { return std::isfinite(x); }) &&
                        std::all_of(a.begin(), a.end(), [](float x) { return std::isfinite(x); });
    if (!finite) {
        r.add(Rule::V19, std::string(kAttrCubeCentre) + " or " + kAttrCubeAxes + " holds a non-finite value");
        return false;
    }
    centre = glm::dvec3(c[0], c[1], c[2]);
    glm::dvec3 row[3];
    for (int i = 0; i < 3; ++i) row[i] = glm::dvec3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
    bool rotation = true;
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
            rotation &= std::abs(glm::dot(row[i], row[j]) - (i == j ? 1.0 : 0.0)) <= kTolerance;
    if (!rotation || !(glm::dot(glm::cross(row[0], row[1]), row[2]) > 0)) {
        r.add(Rule::V19, std::string(kAttrCubeAxes) + " rows " + vectorText(row[0]) + ", " + vectorText(row[1]) + ", " +
                             vectorText(row[2]) + " are not orthonormal and right-handed");
        return false;
    }
    for (int i = 0; i < 3; ++i) axes[i] = row[i];
    return true;
}

// V19's second half: face f's camera is its face's (eye at the centre, looking along its axis with
// its up, 90 degrees, square): points one unit ahead land at the image's centre and edges.
void checkFaceCamera(int f, const HeaderModel& m, glm::dvec3 centre, const glm::dmat3& axes, ValidationReport& r) {
    const CameraCheck check = describeCamera(CameraAttributes{m.projection.value, m.worldToCamera.value, m.worldToNDC.value});
    if (!check.camera) return;  // V13 said why
    const Camera& camera = *check.camera;
    const std::string name = "face " + faceName(f) + "'s camera";
    if (camera.projection() != Projection::Perspective) {
        r.add(Rule::V19, name + " is " + enumName(camera.projection()) + ", not perspective");
        return;
    }
    const double scale = 1.0 + glm::length(centre);
    if (glm::distance(camera.eye(), centre) > kTolerance * scale) {
        r.add(Rule::V19, name + " has its eye at " + vectorText(camera.eye()) + ", not at the cube's centre " + vectorText(centre));
        return;
    }
    const auto& t = kCubeFaceAxes[static_cast<std::size_t>(f)];
    const glm::dvec3 forward = axes * glm::dvec3(t[0], t[1], t[2]), up = axes * glm::dvec3(t[3], t[4], t[5]);
    const glm::dvec3 right = glm::cross(forward, up);
    const struct {
        glm::dvec3 offset;
        glm::dvec2 uv;
    } expected[] = {{forward, {0.5, 0.5}}, {forward + up, {0.5, 0.0}}, {forward + right, {1.0, 0.5}}};
    for (const auto& e : expected) {
        const glm::dvec3 q = camera.project(centre + e.offset);
        if (!(q.z > 0) || !(glm::distance(glm::dvec2(q), e.uv) <= 1e-3)) {
            r.add(Rule::V19, name + " does not look along the cube's " + (f % 2 ? "-" : "+") + std::string(1, "xyz"[f / 2]) +
                                 " axis " + vectorText(forward) + " with a square 90 degree view");
            return;
        }
    }
}

}  // namespace

HeaderCheck checkAssetRules(const AssetModel& faces, const Limits& limits, ValidationReport& r) {
    HeaderCheck hc;
    bool complete = true;
    for (int f = 0; f < kCubeFaceCount; ++f) {
        const HeaderModel& m = faces[static_cast<std::size_t>(f)];
        if (m.slot(PartKind::Conus).count == 0) {
            r.add(Rule::V18, "no part `" + m.partName(PartKind::Conus) + "`: a reflection asset holds the six faces px, nx, py, ny, "
                                                                         "pz, nz, each in parts conus.<face> and samplingmap.<face>");
            complete = false;
            continue;
        }
        ValidationReport face;
        const HeaderCheck one = checkHeaderRules(m, limits, face);
        hc.limitExceeded |= one.limitExceeded;
        for (const Issue& issue : face.issues) {
            // Every face's model sees all of the file's parts: the shared display window is said once.
            if (issue.rule == Rule::V15 && f > 0) continue;
            r.add(issue.rule, "face " + faceName(f) + ": " + issue.message, issue.count);
        }
    }
    if (!complete) return hc;
    checkFaces(faces, r);
    glm::dvec3 centre(0.0);
    glm::dmat3 axes(1.0);
    if (!checkFrame(faces[0], centre, axes, r)) return hc;
    // Faces that share an eye elsewhere than the centre: the frame's centre is what is wrong, said once.
    std::optional<glm::dvec3> eye;
    for (const HeaderModel& m : faces) {
        const CameraCheck check = describeCamera(CameraAttributes{m.projection.value, m.worldToCamera.value, m.worldToNDC.value});
        if (!check.camera || (eye && glm::distance(*eye, check.camera->eye()) > kTolerance * (1.0 + glm::length(*eye)))) {
            eye.reset();
            break;
        }
        eye = check.camera->eye();
    }
    if (eye && glm::distance(*eye, centre) > kTolerance * (1.0 + glm::length(centre))) {
        r.add(Rule::V19, std::string(kAttrCubeCentre) + " " + vectorText(centre) + " is not the faces' eye " + vectorText(*eye));
        return hc;
    }
    for (int f = 0; f < kCubeFaceCount; ++f) checkFaceCamera(f, faces[static_cast<std::size_t>(f)], centre, axes, r);
    return hc;
}

AssetModel modelOf(const ReflectionAssetFile& asset) {
    AssetModel models;
    for (int f = 0; f < kCubeFaceCount; ++f) models[static_cast<std::size_t>(f)] = modelOf(asset.faces[static_cast<std::size_t>(f)], faceSuffix(f));
    HeaderModel& first = models[0];
    first.cubeCentre.present = first.cubeCentre.typeOk = true;
    first.cubeCentre.value = asset.frame.centre;
    first.cubeAxes.present = first.cubeAxes.typeOk = true;
    first.cubeAxes.value = asset.frame.axes;
    return models;
}

}  // namespace detail

ValidationReport validateReflectionAsset(const ReflectionAssetFile& asset) {
    ValidationReport report;
    const detail::AssetModel models = detail::modelOf(asset);
    detail::checkAssetRules(models, Limits{}, report);
    for (int f = 0; f < kCubeFaceCount; ++f)
        detail::checkPixelsAndMap(asset.faces[static_cast<std::size_t>(f)], "face " + std::string(kCubeFaceNames[f]) + ": ", report);
    return report;
}

}  // namespace conus::format
