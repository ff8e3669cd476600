// conus-view's command line (CLI11): what to open and how, parsed into plain values.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/decode.h"
#include "actions.h"
#include "conus/renderers/mesh_render.h"
#include "conus/renderers/view_renderer.h"

namespace conus::viewer {

// --mode's value that shows a depth image's Z as a picture (beside the renderers::ViewMode names).
inline constexpr const char* kDepthPictureMode = "z";

// The 3-D modes (scene.h): what is rendered live instead of CoNUS files being viewed.
enum class SceneKind { None, Mesh, Volume, Relief, Reflection };

struct Options {
    std::vector<std::string> files;      // CoNUS files to view
    std::string edit;                    // --edit IMAGE: the map editor on this image
    std::string output;                  // --edit: base path of the saved map / CoNUS file
    std::string screenshot;              // --screenshot OUT.png: render offscreen and exit
    std::string uniform;                 // --uniform FILE: the first file's real uniform baseline
    std::optional<codec::View> view;     // --view u0,v0,u1,v1
    int width = 0, height = 0;           // --size: screenshot size, or the editor's encode size
    int windowWidth = 1280, windowHeight = 800;
    renderers::ViewOptions display;             // --mode, --grid, --outlines, --exposure, --tonemap, --gamma
    std::string script;                  // --script CMDS.txt
    int benchmarkFrames = 0;             // --benchmark-frames N
    std::string backend = enumName(renderers::Backend::Auto);  // --backend for --screenshot
    bool helpOverlay = false;            // --help-overlay: start with the key list (H) shown
    bool statusBar = false;              // --status-bar: start with the status bar (B) shown
    // 3-D modes: --mesh FILE, --volume SPEC, --relief ASSET or --reflection ASSET (with --scene MESH);
    // --uniform is then the conventional asset of a relief or reflection; --size the frame's size.
    SceneKind sceneKind = SceneKind::None;
    std::string scenePath;
    std::string reflectionScene;         // --scene: the mesh a reflection asset was baked from
    std::vector<std::string> allowDirs;  // --allow-dir: folders a scene file may also name files in
    double reflectorRadius = 0.5;        // --radius: the mirror sphere of --reflection
    std::string transferFunction;        // --tf: a volume's transfer function preset or file
    double maxEdge = 0;                  // --max-edge: --mesh subdivides each CoNUS frame's mesh (0: never)
    double maxBend = renderers::kDefaultMaxBend;  // --max-bend: --mesh's GPU split where the map bends (0: none)
    std::vector<codec::Focus> foci;      // --focus u,v,r,k (repeated): the 3-D modes' first foci
    bool depthPicture = false;           // --mode z: a depth image's Z as a picture (key Z)
};

// Parses argv. Returns nullopt after printing help (exit 0) or an error (exit 2, in *exitCode).
std::optional<Options> parseOptions(int argc, char** argv, int* exitCode);


}  // namespace conus::viewer
