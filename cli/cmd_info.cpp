// conus info: what a CoNUS file holds, as text or JSON, and a picture of its sampling density.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include "commands.h"
#include "conus/codec/builders/map_measures.h"
#include "conus/codec/map/pictures.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "conus/format/reflection_asset.h"
#include "conus/core/bounds.h"
#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/renderers/context.h"
#include "conus/sceneio/mesh_file.h"
#include "image_files.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {

namespace {

int printBackends(bool json) {
    const std::vector<renderers::BackendStatus> statuses = renderers::probeBackends();
    if (json) {
        nlohmann::ordered_json j = nlohmann::ordered_json::array();
        for (const auto& s : statuses)
            j.push_back({{"backend", enumName(s.backend)},
                         {"works", s.works},
                         {"renderer", s.renderer},
                         {"version", s.version},
                         {"reason", s.reason}});
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    for (const auto& s : statuses) {
        std::printf("%-7s %-10s %s\n", enumName(s.backend), s.works ? "works" : "unavailable",
                    s.works ? (s.renderer + (s.version.empty() ? "" : " (" + s.version + ")")).c_str() : "");
        if (!s.reason.empty()) std::printf("        %s\n", s.reason.c_str());
    }
    return 0;
}

// The caps every reader applies (limits.h), as the spec's "Limits" section lists them.
int printLimits(bool json) {
    if (json) {
        nlohmann::ordered_json j;
        for (const LimitEntry& l : limitTable()) j[l.name] = {{"value", l.value}, {"unit", l.unit}, {"meaning", l.meaning}};
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    for (const LimitEntry& l : limitTable())
        std::printf("%-18s %12lld %-8s %s\n", l.name, static_cast<long long>(l.value), l.unit, l.meaning);
    return 0;
}

struct InfoOptions {
    std::string input, densityPng;
    bool json = false, backends = false, limits = false, verbose = false;
};

// --verbose on an invalid file: every broken rule, one a line (as `conus validate`), then the error.
void explainIfInvalid(const std::string& input) {
    const format::ValidationReport report = format::validateConusFile(input, {}, false);
    if (report.ok()) return;
    for (const auto& issue : report.issues)
        std::printf("%s: %s: %s\n", input.c_str(), format::label(issue.rule).c_str(), issue.message.c_str());
    throw Error(ErrorCode::Corrupt, input + ": not a valid CoNUS file (" +
                                        plural(static_cast<std::size_t>(report.problemCount()), "problem", "problems") + ")");
}

// What info reports about one file, read once.
struct FileFacts {
    format::ConusFile file;  // everything but the image's pixels, which nothing here needs
    std::vector<std::string> channels;  // display order
    codec::SamplingMap map;
    codec::DensityStats stats;
    codec::MapMeasures measures;  // anisotropy in the source's pixels
    std::optional<Camera> camera;
    double pixelRatio = 0;  // CoNUS pixels over source pixels
};

FileFacts factsOf(format::ConusFile file) {
    codec::SamplingMap map = codec::SamplingMap::fromGrid(file.map);
    const codec::DensityStats stats = codec::densityStats(map);
    const codec::MapMeasures measures = codec::measureMap(map, double(file.sourceWidth) / file.sourceHeight);
    std::optional<Camera> camera = file.camera ? std::optional<Camera>(format::toCamera(*file.camera)) : std::nullopt;
    const double ratio = double(file.image.width) * file.image.height / (double(file.sourceWidth) * file.sourceHeight);
    std::vector<std::string> channels = displayOrder(file.image.channels);
    return {std::move(file), std::move(channels), std::move(map), stats, measures, camera, ratio};
}

FileFacts readFacts(const std::string& input) { return factsOf(format::readConusHeader(input)); }

// A file's facts (an asset's face has no "file" or "formatVersion" of its own: `input` empty).
nlohmann::ordered_json toJson(const std::string& input, const FileFacts& f) {
    const format::ConusFile& file = f.file;
    nlohmann::ordered_json j;
    if (!input.empty()) {
        j["file"] = input;
        j["formatVersion"] = format::kFormatVersion;
    }
    j["dataKind"] = enumName(file.dataKind);
    j["image"] = {{"width", file.image.width},
                  {"height", file.image.height},
                  {"channels", f.channels},
                  {"pixelType", enumName(file.pixelType)},
                  {"compression", enumName(file.compression)}};
    j["source"] = {{"width", file.sourceWidth}, {"height", file.sourceHeight}};
    j["pixelRatio"] = f.pixelRatio;
    j["samplingMap"] = {{"columns", f.map.columns()},
                        {"rows", f.map.rows()},
                        {"densityMin", f.stats.min},
                        {"densityMax", f.stats.max},
                        {"densityMean", f.stats.mean},
                        {"maxAnisotropy", f.measures.maxAnisotropy},
                        {"mostAnisotropicAt", {f.measures.mostAnisotropic.x, f.measures.mostAnisotropic.y}}};
    if (file.analytic) {
        nlohmann::ordered_json a{{"kind", file.analytic->kind}};
        if (file.analytic->is(format::MapKind::Foci)) {
            a["composition"] = file.analytic->composition;
            for (const auto& focus : file.analytic->foci)
                a["foci"].push_back({{"u", focus.u}, {"v", focus.v}, {"r", focus.r}, {"k", focus.k}});
        }
        for (const auto& [name, value] : file.analytic->scalars) a["params"][name] = value;
        j["analyticMap"] = a;
    }
    if (f.camera) {
        const glm::dvec3 eye = f.camera->eye(), forward = f.camera->forward();
        j["camera"] = {{"projection", file.camera->projection},
                       {"eye", {eye.x, eye.y, eye.z}},
                       {"forward", {forward.x, forward.y, forward.z}},
                       {"worldToCamera", file.camera->worldToCamera},
                       {"worldToNDC", file.camera->worldToNDC}};
        if (f.camera->projection() == Projection::Perspective) j["camera"]["verticalFov"] = f.camera->verticalFovDegrees();
    }
    if (file.depth.kind != format::DepthKind::None)
        j["depth"] = {{"kind", enumName(file.depth.kind)},
                      {"units", file.depth.units},
                      {"near", file.depth.near},
                      {"far", file.depth.far}};
    if (!file.software.empty()) j["software"] = file.software;
    const SourceEncoding& encoding = file.sourceEncoding;
    nlohmann::ordered_json colour{{"sourceTransfer", enumName(encoding.transfer)}};
    if (encoding.sampleType) colour["sourceSampleType"] = enumName(*encoding.sampleType);
    if (encoding.chromaticities) colour["chromaticities"] = *encoding.chromaticities;
    colour["iccProfileBytes"] = encoding.iccProfile.size();
    for (const MetadataItem& item : encoding.metadata)
        std::visit([&](const auto& v) { colour["metadata"][item.name] = v; }, item.value);
    j["colour"] = colour;
    return j;
}

void printColour(const SourceEncoding& encoding, bool verbose) {
    std::printf("  colour        %s%s%s\n",
                encoding.transfer == Transfer::Raw ? "raw data (never converted)" : "linear light, associated alpha",
                encoding.sampleType ? (std::string("; source ") + enumName(encoding.transfer) + " " + enumName(*encoding.sampleType)).c_str()
                                    : "",
                encoding.iccProfile.empty() ? "" : (", ICC profile of " + std::to_string(encoding.iccProfile.size()) + " bytes").c_str());
    if (!verbose) return;
    for (const MetadataItem& item : encoding.metadata) {
        std::string value;
        std::visit([&](const auto& v) {
            if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::string>) value = v;
            else value = std::to_string(v);
        }, item.value);
        std::printf("    %s = %s\n", item.name.c_str(), value.c_str());
    }
}

void printText(const InfoOptions& o, const FileFacts& f) {
    const format::ConusFile& file = f.file;
    std::printf("%s: CoNUS file, format version %d, data kind %s\n", o.input.c_str(), format::kFormatVersion,
                enumName(file.dataKind));
    std::string channelList;
    for (const auto& c : f.channels) channelList += (channelList.empty() ? "" : ",") + c;
    std::printf("  CoNUS image   %d x %d, channels %s, %s, %s compression\n", file.image.width, file.image.height,
                channelList.c_str(), enumName(file.pixelType), enumName(file.compression));
    printColour(file.sourceEncoding, o.verbose);
    std::printf("  source        %d x %d (CoNUS image holds %.2f%% of its pixels)\n", file.sourceWidth, file.sourceHeight,
                100.0 * f.pixelRatio);
    std::printf("  sampling map  %d x %d nodes; density min %.3f, max %.3f, mean %.3f\n", f.map.columns(), f.map.rows(),
                f.stats.min, f.stats.max, f.stats.mean);
    std::printf("  anisotropy    up to %.3g (a CoNUS pixel's footprint that many times longer than wide), at %.3f,%.3f\n",
                f.measures.maxAnisotropy, f.measures.mostAnisotropic.x, f.measures.mostAnisotropic.y);
    if (file.analytic) {
        std::printf("  analytic map  %s", file.analytic->kind.c_str());
        if (file.analytic->is(format::MapKind::Foci)) {
            std::printf(" (%s composition)", file.analytic->composition.c_str());
            for (const auto& focus : file.analytic->foci)
                std::printf("\n    focus u=%g v=%g r=%g k=%g", focus.u, focus.v, focus.r, focus.k);
        }
        for (const auto& [name, value] : file.analytic->scalars) std::printf("\n    %s = %g", name.c_str(), value);
        std::printf("\n");
    }
    if (f.camera) {
        const glm::dvec3 eye = f.camera->eye(), forward = f.camera->forward();
        std::printf("  camera        %s, eye (%g, %g, %g), looking along (%.4g, %.4g, %.4g)", enumName(f.camera->projection()),
                    eye.x, eye.y, eye.z, forward.x, forward.y, forward.z);
        if (f.camera->projection() == Projection::Perspective) std::printf(", vertical fov %.4g deg", f.camera->verticalFovDegrees());
        std::printf("\n");
    }
    if (file.depth.kind != format::DepthKind::None)
        std::printf("  depth         %s in [%g, %g] %s\n", enumName(file.depth.kind), file.depth.near, file.depth.far,
                    file.depth.units.c_str());
    if (!o.densityPng.empty()) std::printf("  density       written to %s\n", o.densityPng.c_str());
}

// The density as a heat map with the sampling pattern over it, covering the conventional frame at
// most 1024 px on its long side.
void writeDensityPicture(const std::string& path, const FileFacts& f) {
    const format::ConusFile& file = f.file;
    const double scale = 1024.0 / std::max(file.sourceWidth, file.sourceHeight);
    const int w = std::max(16, static_cast<int>(file.sourceWidth * std::min(1.0, scale)));
    const int h = std::max(16, static_cast<int>(file.sourceHeight * std::min(1.0, scale)));
    const int lines = std::max(8, std::min(64, file.image.width / 8));
    writeDrawing(path, codec::densityPicture(f.map, w, h, lines, file.analytic ? &*file.analytic : nullptr,
                                      double(file.sourceWidth) / file.sourceHeight));
}

// The layers a reflection asset's face keeps (spec "Layers": layer k >= 1 in `layer<k>.*`).
int faceLayers(const format::ConusFile& face) {
    int layers = 1;
    while (face.image.channelIndex("layer" + std::to_string(layers) + ".Z") >= 0) ++layers;
    return layers;
}

// Where a face's texels went: the part of the face its map magnifies (density above 1), as a
// share of the face's area and of its texels (CoNUS pixels whose undistorted centre lies there),
// and that part's centre (u, v); a uniform face spends the area's share on it.
struct MagnifiedShare {
    double area = 0, texels = 0;
    glm::dvec2 centre{0.5};
};
MagnifiedShare magnifiedShare(const FileFacts& face) {
    const int w = face.file.image.width, h = face.file.image.height;
    MagnifiedShare share;
    glm::dvec2 sum(0.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::dvec2 p((x + 0.5) / w, (y + 0.5) / h);
            if (face.map.density(p) > 1.0) {
                share.area += 1;
                sum += p;
            }
            share.texels += face.map.density(face.map.undistort(p)) > 1.0;
        }
    if (share.area > 0) share.centre = sum / share.area;
    share.area /= double(w) * h;
    share.texels /= double(w) * h;
    return share;
}

// A reflection asset: its frame, then each face in a line (JSON: each face as a file's facts).
int printReflectionAsset(const InfoOptions& o) {
    if (!o.densityPng.empty())
        throw Error(ErrorCode::InvalidArgument, "--density draws one image's map; " + o.input + " is a reflection asset of six faces");
    const format::ReflectionAssetFile asset = format::readReflectionAssetHeader(o.input);
    const auto& c = asset.frame.centre;
    const auto& a = asset.frame.axes;
    std::vector<FileFacts> faces;
    for (const format::ConusFile& face : asset.faces) faces.push_back(factsOf(face));
    if (o.json) {
        nlohmann::ordered_json j;
        j["file"] = o.input;
        j["formatVersion"] = format::kFormatVersion;
        j["kind"] = "reflectionAsset";
        j["layers"] = faceLayers(asset.faces.front());
        j["cubeFrame"] = {{"centre", c}, {"axes", {{a[0], a[1], a[2]}, {a[3], a[4], a[5]}, {a[6], a[7], a[8]}}}};
        for (std::size_t f = 0; f < faces.size(); ++f) {
            nlohmann::ordered_json face{{"name", format::kCubeFaceNames[f]}};
            face.update(toJson("", faces[f]));
            const MagnifiedShare share = magnifiedShare(faces[f]);
            face["magnified"] = {{"areaShare", share.area}, {"texelShare", share.texels}, {"centre", {share.centre.x, share.centre.y}}};
            j["faces"].push_back(face);
        }
        std::printf("%s\n", j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace).c_str());
        return 0;
    }
    const format::ConusFile& first = faces.front().file;
    std::string channelList;
    for (const auto& name : faces.front().channels) channelList += (channelList.empty() ? "" : ",") + name;
    const int layers = faceLayers(asset.faces.front());
    std::printf("%s: CoNUS reflection asset, format version %d: six %d x %d faces of %d layer%s, channels %s, %s, %s compression\n",
                o.input.c_str(), format::kFormatVersion, first.image.width, first.image.height, layers, layers == 1 ? "" : "s",
                channelList.c_str(), enumName(first.pixelType), enumName(first.compression));
    std::printf("  cube frame    centre (%g, %g, %g); axes +x (%g, %g, %g), +y (%g, %g, %g), +z (%g, %g, %g)\n", c[0], c[1], c[2],
                a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8]);
    for (std::size_t f = 0; f < faces.size(); ++f) {
        const FileFacts& face = faces[f];
        const glm::dvec3 forward = (face.camera ? face.camera->forward() : glm::dvec3(0.0)) + 0.0;  // no -0
        std::printf("  face %s       looking along (%.4g, %.4g, %.4g); map %d x %d nodes, density %.3f..%.3f", format::kCubeFaceNames[f],
                    forward.x, forward.y, forward.z, face.map.columns(), face.map.rows(), face.stats.min, face.stats.max);
        if (face.file.analytic && face.file.analytic->is(format::MapKind::Foci))
            for (const auto& focus : face.file.analytic->foci)
                std::printf("; focus u=%.3g v=%.3g r=%.3g k=%.3g", focus.u, focus.v, focus.r, focus.k);
        if (const MagnifiedShare share = magnifiedShare(face); share.area > 0)
            std::printf("; magnified about u=%.2f v=%.2f: %.1f%% of the face, %.1f%% of its texels", share.centre.x, share.centre.y,
                        100.0 * share.area, 100.0 * share.texels);
        std::printf("; depth [%g, %g] %s\n", face.file.depth.near, face.file.depth.far, face.file.depth.units.c_str());
    }
    return 0;
}

// Whether the file begins with OpenEXR's magic number (every CoNUS file and asset does).
bool isExr(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::array<unsigned char, 4> magic{};
    in.read(reinterpret_cast<char*>(magic.data()), magic.size());
    return in && magic == std::array<unsigned char, 4>{0x76, 0x2f, 0x31, 0x01};
}

// A mesh file (what `bake reflection`, `render mesh` take): its size and bounds, so that --center
// and --roi-min/--roi-max can be chosen without another tool.
int printMesh(const InfoOptions& o, const Mesh& mesh) {
    const AxisBox box = boundsOf(mesh);
    const glm::dvec3 size = box.hi - box.lo, centre = 0.5 * (box.lo + box.hi) + 0.0;  // + 0.0: no -0
    const std::size_t triangles = mesh.indices.size() / 3, vertices = mesh.positions.size();
    if (o.json) {
        nlohmann::ordered_json j;
        j["file"] = o.input;
        j["kind"] = "mesh";
        j["triangles"] = triangles;
        j["vertices"] = vertices;
        j["bounds"] = {{"min", {box.lo.x, box.lo.y, box.lo.z}}, {"max", {box.hi.x, box.hi.y, box.hi.z}},
                       {"centre", {centre.x, centre.y, centre.z}}, {"size", {size.x, size.y, size.z}}};
        j["colours"] = !mesh.colours.empty();
        if (mesh.texture) j["texture"] = {{"width", mesh.texture->width}, {"height", mesh.texture->height}};
        std::printf("%s\n", j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace).c_str());
        return 0;
    }
    std::printf("%s: mesh, %zu triangles, %zu vertices%s", o.input.c_str(), triangles, vertices,
                mesh.colours.empty() ? "" : ", vertex colours");
    if (mesh.texture) std::printf(", a %d x %d texture", mesh.texture->width, mesh.texture->height);
    std::printf("\n");
    std::printf("  bounds        min %g,%g,%g  max %g,%g,%g\n", box.lo.x, box.lo.y, box.lo.z, box.hi.x, box.hi.y, box.hi.z);
    std::printf("  centre        %g,%g,%g  size %g x %g x %g\n", centre.x, centre.y, centre.z, size.x, size.y, size.z);
    return 0;
}

int runInfo(const InfoOptions& o) {
    if (o.backends) return printBackends(o.json);
    if (o.limits) return printLimits(o.json);
    if (o.input.empty()) throw Error(ErrorCode::InvalidArgument, "give a CoNUS file (or --backends, --limits)");
    if (!o.densityPng.empty()) checkPictureOutput(o.densityPng, {}, {o.input});  // before the file is read
    if (o.verbose) explainIfInvalid(o.input);
    if (format::isReflectionAsset(o.input)) return printReflectionAsset(o);
    // Not OpenEXR: a mesh file when Assimp reads it; otherwise both readers' reasons.
    if (std::filesystem::is_regular_file(o.input) && !isExr(o.input)) {
        Mesh mesh;
        try {
            mesh = sceneio::readMesh(o.input);
        } catch (const Error& e) {
            throw Error(e.code(), o.input + " is not an OpenEXR file (what CoNUS files and assets are), nor a mesh file this tool reads: " +
                                      e.what());
        }
        if (!o.densityPng.empty()) throw Error(ErrorCode::InvalidArgument, "--density draws a CoNUS file's map; " + o.input + " is a mesh");
        return printMesh(o, mesh);
    }
    const FileFacts facts = readFacts(o.input);
    nlohmann::ordered_json j = toJson(o.input, facts);
    if (!o.densityPng.empty()) {
        writeDensityPicture(o.densityPng, facts);
        j["densityPicture"] = o.densityPng;
    }
    if (o.json) {
        // Attribute strings come from the file and need not be UTF-8: invalid bytes become U+FFFD
        // rather than failing the whole dump.
        std::printf("%s\n", j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace).c_str());
        return 0;
    }
    printText(o, facts);
    return 0;
}

}  // namespace

CLI::App* declareInfo(CLI::App& root, InfoOptions& options) {
    CLI::App* command = root.add_subcommand("info", "Describe a CoNUS file: image, sampling map, camera, depth (a reflection asset: its frame and six faces; a mesh: its bounds)");
    command->add_option("input", options.input, "CoNUS file or reflection asset (.exr), or a mesh file (its bounds and size)");
    command->add_flag("--backends", options.backends,
                      "list the rendering backends (EGL, OSMesa, CPU): whether each works, its GL_RENDERER, why not");
    command->add_flag("--limits", options.limits,
                      "print the resource limits every reader checks before allocating (image, map, header, "
                      "index, decode memory)");
    command->add_flag("--json", options.json, "print JSON instead of text");
    command->add_flag("-v,--verbose", options.verbose,
                      "also list the source's metadata; for an invalid file, every broken rule (as `conus validate`)");
    setExamples(*command, {"conus info photo.exr",
                       "conus info photo.exr --json --density density.png",
                       "conus info asset.exr                # a reflection asset: the cube's frame and its six faces",
                       "conus info teapot.obj               # a mesh: triangles, vertices, bounds (for --center, --roi-min/--roi-max)",
                       "conus info --backends"});
    writesFile(command->add_option("--density", options.densityPng,
                                   "write the sampling density as a heat map with the sampling pattern over it (.png)"));
    return command;  // --quiet: progress only, the description is what info is for
}

Command addInfoCommand(CLI::App& root) { return defineCommand(root, declareInfo, runInfo); }

}  // namespace conus::cli
