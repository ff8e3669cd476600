#include "options.h"

#include <cmath>

#include <cstdio>
#include <sstream>

#include <CLI/CLI.hpp>

#include "conus/cli/option_checks.h"
#include "conus/core/atomic_file.h"
#include "conus/core/error.h"

namespace conus::viewer {
namespace {

constexpr const char* kDescription =
    "conus-view: a small viewer for CoNUS files (coherent non-uniform sampling images).\n"
    "The frame is reconstructed from the CoNUS data at every zoom level (GPU shader, or the CPU decoder on software GL).\n"
    "Press H in the window for the keys. --edit IMAGE opens the mass-spring map editor.\n"
    "3-D modes (--mesh, --volume, --relief, --reflection) render the CoNUS frame live and show it as the paper's\n"
    "focus-plus-context display: orbit with the arrows or a drag, drag a focus, U toggles CoNUS / conventional.";

std::pair<int, int> parseSize(const std::string& text, const char* what) {
    int w = 0, h = 0;
    char x = 0;
    std::istringstream in(text);
    if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || !in.eof() || w < 1 || h < 1 || w > 16384 || h > 16384)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + " \"" + text + "\" is not WxH (1 .. 16384)");
    return {w, h};
}

codec::View parseView(const std::string& text) {
    codec::View v;
    char c1 = 0, c2 = 0, c3 = 0;
    std::istringstream in(text);
    if (!(in >> v.u0 >> c1 >> v.v0 >> c2 >> v.u1 >> c3 >> v.v1) || c1 != ',' || c2 != ',' || c3 != ',' || !in.eof() ||
        v.u0 == v.u1 || v.v0 == v.v1 || !(std::abs(v.u0) <= 1e3 && std::abs(v.u1) <= 1e3 && std::abs(v.v0) <= 1e3 &&
                                           std::abs(v.v1) <= 1e3))
        throw Error(ErrorCode::InvalidArgument, "--view \"" + text + "\" is not u0,v0,u1,v1 with u0 != u1, v0 != v1, each within 1000 of the image");
    return v;
}

// "u,v,r,k" -> a focus, checked as every builder of foci checks one.
codec::Focus parseFocus(const std::string& text) {
    codec::Focus f;
    char c1 = 0, c2 = 0, c3 = 0;
    std::istringstream in(text);
    if (!(in >> f.u >> c1 >> f.v >> c2 >> f.r >> c3 >> f.k) || c1 != ',' || c2 != ',' || c3 != ',' || !in.eof())
        throw Error(ErrorCode::InvalidArgument, "--focus \"" + text + "\" is not u,v,r,k");
    try {
        codec::checkFocus(f);
    } catch (const Error& e) {
        throw Error(ErrorCode::InvalidArgument, "--focus \"" + text + "\": " + e.what());
    }
    return f;
}

}  // namespace

std::optional<Options> parseOptions(int argc, char** argv, int* exitCode) {
    Options o;
    std::string view, size, window = "1280x800", mode = enumName(renderers::ViewMode::Reconstructed);
    std::string decode = enumName(renderers::DecodePath::Auto), toneMap = enumName(ToneMap::None);
    std::string mesh, volume, relief, reflection;
    std::vector<std::string> foci;
    CLI::App app(kDescription, "conus-view");
    app.add_option("files", o.files, "CoNUS files (.exr), or pictures with --focus; Tab / PageDown switch between them");
    app.add_option("--edit", o.edit, "paint a sampling map over IMAGE (PNG, JPEG, EXR, ...)");
    app.add_option("-o,--output", o.output, "--edit: base path for S (<base>.map.exr) and Ctrl-S (<base>.conus.exr)");
    app.add_option("--screenshot", o.screenshot,
                   "render the first file, or a 3-D mode's first frame, offscreen (no display needed) to a PNG and exit");
    app.add_option("--uniform", o.uniform,
                   "the first file's uniform baseline for U and W (a CoNUS file `conus uniform` wrote from the same source; "
                   "without it, the uniform image is resampled from the CoNUS data)");
    app.add_option("--mesh", mesh, "3-D mode: render this mesh (OBJ, PLY, glTF, ...) live through the flexible pinhole camera");
    app.add_option("--volume", volume, "3-D mode: ray-cast this volume live (.den, .nrrd, .vdb, raw:..., procedural:...)");
    app.add_option("--relief", relief, "3-D mode: orbit a relief asset (`conus bake relief`); --uniform: its conventional twin");
    app.add_option("--reflection", reflection,
                   "3-D mode: orbit a reflection asset (.exr from `conus bake reflection`) with --scene; --uniform: its conventional twin");
    app.add_option("--scene", o.reflectionScene, "--reflection: the mesh the asset was baked from");
    cli::addAllowDirOption(app, o.allowDirs);
    app.add_option("--radius", o.reflectorRadius, "--reflection: the mirror sphere's radius")->capture_default_str()->check(cli::finiteRange(0.0, 1e9));
    app.add_option("--max-bend", o.maxBend,
                   "--mesh: split triangles on the GPU where Equation 1 bends an edge or a triangle's inside more than "
                   "this many CoNUS pixels away from the straight lines the rasterizer draws (0: draw them as they are)")
        ->capture_default_str()
        ->check(cli::finiteRange(0.0, 1e6, true, true));
    app.add_option("--max-edge", o.maxEdge,
                   "--mesh: instead of splitting on the GPU where the map bends, split triangles each CoNUS frame until no "
                   "projected edge spans more than this many map cells (a CPU subdivision and an upload a frame; 0: never)")
        ->capture_default_str()
        ->check(cli::finiteRange(0.0, 1e6, true, true));
    app.add_option("--tf", o.transferFunction, "--volume: transfer function preset or file (T cycles the presets)");
    app.add_option("--focus", foci,
                   "a focus u,v,r,k (repeat for more). 3-D modes: the first foci (N adds one at the cursor); with files: "
                   "each file is a picture (PNG, JPEG, EXR, ...) shown as `conus encode --focus` writes it");
    app.add_option("--view", view, "undistorted rectangle u0,v0,u1,v1 to show");
    app.add_option("--size", size, "WxH of --screenshot, or of the CoNUS image --edit encodes");
    app.add_option("--window", window, "window size WxH")->capture_default_str();
    app.add_option("--mode", mode, "one of " + enumChoices<renderers::ViewMode>() + ", or " + kDepthPictureMode + " (a depth image's Z as a picture)")
        ->capture_default_str();
    app.add_flag("--grid", o.display.grid, "draw the CoNUS pixel grid");
    app.add_option("--grid-every", o.display.gridEvery, "draw every n-th grid line (0: automatic)");
    app.add_flag("--outlines", o.display.outlines, "draw the focus outlines");
    app.add_option("--exposure", o.display.exposure, "exposure in stops")->check(cli::finiteRange(-64.0, 64.0, true, true));
    app.add_option("--tonemap", toneMap, "tone map for HDR values")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames<ToneMap>()));
    app.add_option("--gamma", o.display.gamma,
                   "display curve: 0 (default) the sRGB curve for linear data, else a display gamma (1: linear)")
        ->check(cli::finiteRange(0.0, 10.0, true, true));
    app.add_option("--decode", decode,
                   "where the reconstructed frame is decoded: the shader, or codec::decodeImage each frame, uploaded; "
                   "auto: the shader, except on a software rasterizer (llvmpipe, softpipe, swrast) where the view is not "
                   "zoomed out: the CPU, the faster there")
        ->check(CLI::IsMember(enumNames<renderers::DecodePath>()))
        ->capture_default_str();
    app.add_option("--script", o.script, "run window commands from a file, then exit (see viewer/script.h)");
    app.add_option("--benchmark-frames", o.benchmarkFrames, "draw N frames, print frames/s and exit");
    app.add_flag("--help-overlay", o.helpOverlay, "show the key list (H) over the view, in the window and in --screenshot");
    app.add_flag("--status-bar", o.statusBar, "show the status bar (B): file, mode, zoom, the pixel under the cursor");
    app.add_option("--backend", o.backend, "--screenshot's GL backend")
        ->capture_default_str()
        ->check(CLI::IsMember(enumNames({renderers::Backend::Auto, renderers::Backend::Egl, renderers::Backend::OsMesa}), CLI::ignore_case));
    try {
        app.parse(argc, argv);
        if (!view.empty()) o.view = parseView(view);
        if (!size.empty()) std::tie(o.width, o.height) = parseSize(size, "--size");
        std::tie(o.windowWidth, o.windowHeight) = parseSize(window, "--window");
        o.depthPicture = mode == kDepthPictureMode;
        const std::optional<renderers::ViewMode> viewMode = tryParseEnum<renderers::ViewMode>(mode);
        if (!o.depthPicture && !viewMode)
            throw Error(ErrorCode::InvalidArgument, "--mode '" + mode + "' is not one of " + enumChoices<renderers::ViewMode>() + ", " + kDepthPictureMode);
        o.display.mode = viewMode.value_or(renderers::ViewMode::Reconstructed);
        o.display.toneMap = parseEnum<ToneMap>(toneMap);
        o.display.decode = parseEnum<renderers::DecodePath>(decode);
        const std::pair<SceneKind, const std::string*> scenes[] = {
            {SceneKind::Mesh, &mesh}, {SceneKind::Volume, &volume}, {SceneKind::Relief, &relief}, {SceneKind::Reflection, &reflection}};
        for (const auto& [kind, path] : scenes) {
            if (path->empty()) continue;
            if (o.sceneKind != SceneKind::None) throw Error(ErrorCode::InvalidArgument, "give one of --mesh, --volume, --relief, --reflection");
            o.sceneKind = kind;
            o.scenePath = *path;
        }
        for (const std::string& text : foci) o.foci.push_back(parseFocus(text));
        if (o.sceneKind != SceneKind::None) {
            if (!o.files.empty() || !o.edit.empty())
                throw Error(ErrorCode::InvalidArgument, "a 3-D mode takes no CoNUS files or --edit");
            if (o.sceneKind == SceneKind::Reflection && o.reflectionScene.empty())
                throw Error(ErrorCode::InvalidArgument, "--reflection needs --scene MESH (the mesh the asset was baked from)");
            if (!o.uniform.empty() && o.sceneKind != SceneKind::Relief && o.sceneKind != SceneKind::Reflection)
                throw Error(ErrorCode::InvalidArgument, "--uniform in a 3-D mode is a relief's or reflection's conventional asset "
                                                        "(meshes and volumes: C toggles the identity map)");
        } else if (o.files.empty() && o.edit.empty()) {
            throw Error(ErrorCode::InvalidArgument, "no file given (conus-view FILE.exr, --edit IMAGE, --mesh, --volume, --relief or --reflection)");
        }
        if (!o.edit.empty() && !o.files.empty()) throw Error(ErrorCode::InvalidArgument, "--edit takes no CoNUS files");
        if (!o.screenshot.empty() && o.files.empty() && o.sceneKind == SceneKind::None)
            throw Error(ErrorCode::InvalidArgument, "--screenshot needs a CoNUS file or a 3-D mode");
        if (!o.uniform.empty() && o.files.empty() && o.sceneKind == SceneKind::None) throw Error(ErrorCode::InvalidArgument, "--uniform goes with a CoNUS file");
        if (o.benchmarkFrames < 0) throw Error(ErrorCode::InvalidArgument, "--benchmark-frames must be >= 0");
        // What the viewer reads is never replaced by what it writes (a screenshot, the editor's
        // saves): every file named on the command line but the outputs is protected.
        for (const CLI::Option* option : app.get_options())
            if (option->get_name() != "--screenshot" && option->get_name() != "--output")
                for (const std::string& value : option->results()) protectInput(value);
        if (!o.screenshot.empty()) checkNotAnInput(o.screenshot);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) {  // --help
            *exitCode = app.exit(e);
            return std::nullopt;
        }
        std::string reason = dynamic_cast<const CLI::ExtrasError*>(&e) ? cli::unknownOptionLine(&app, argc, argv) : "";
        if (reason.empty()) reason = oneLine(e.what());
        std::fprintf(stderr, "conus-view: %s (see --help)\n", reason.c_str());  // as conus says a usage error
        *exitCode = 2;
        return std::nullopt;
    } catch (const Error& e) {
        std::fprintf(stderr, "conus-view: %s\n", e.what());
        *exitCode = 2;
        return std::nullopt;
    }
    return o;
}

}  // namespace conus::viewer
