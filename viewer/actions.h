// What conus-view's keys do, independent of GLFW: a key chord (a key name plus Shift/Ctrl) maps
// to an Action, the same table for the keyboard, for --script's `key` command and for the help
// text (H), so the three never disagree.
//
// Key names: letters and digits as upper-case characters ("G", "1"), "+", "-", "[", "]", and
// "Tab", "F5", "Left", "Right", "Up", "Down", "PageUp", "PageDown", "Escape".
#pragma once

#include <optional>
#include <string>

#include "conus/renderers/view_renderer.h"

namespace conus::viewer {

enum class Action {
    None,
    Help,               // H: the key list over the view (and on stdout)
    Fit,                // F
    SourceResolution,   // 1: one source pixel per window pixel
    ZoomIn, ZoomOut,    // + / -
    PanLeft, PanRight, PanUp, PanDown,
    ModeReconstructed,  // C
    ModeRaw,            // R
    ModeUniform,        // U
    ModeWipe,           // W
    ModeDensity,        // D
    ToggleGrid,         // G
    ToggleOutlines,     // O
    ExposureUp, ExposureDown, ResetExposure,  // E, Shift-E, 0
    ToggleGamma,        // L: linear (gamma 1) or the sRGB display curve
    NextToneMap,        // T: none -> reinhard -> aces (values above 1 on the display)
    NextFile, PreviousFile,  // Tab / PageDown, Shift-Tab / PageUp
    Reload,             // Ctrl-R, F5
    Inspect,            // I: print the pixel under the cursor
    ToggleStatusBar,    // B: one line at the bottom: file, mode, zoom, the pixel under the cursor
    Quit,               // Q, Escape
    // Map editor (--edit)
    SaveMap,            // S
    EncodeImage,        // Ctrl-S, E
    StrengthDown, StrengthUp,  // [ ]
    ResetMap,           // Backspace... here: X
};

struct KeyChord {
    std::string key;  // a key name (above)
    bool shift = false, ctrl = false;
};

// "G", "shift+E", "ctrl+R", "Ctrl+Shift+Tab" -> chord; nullopt for an unknown key name.
std::optional<KeyChord> parseChord(const std::string& text);

// The action of a chord; `editing` selects the map editor's table (E encodes there).
Action actionFor(const KeyChord& chord, bool editing);

// One line per key of the table in use.
std::string helpText(bool editing);

// The display modes by name: "reconstructed|raw|uniform|wipe|density" -> ViewMode;
// conus::Error(InvalidArgument) otherwise.
gl::ViewMode parseMode(const std::string& name);
const char* modeName(gl::ViewMode mode);

}  // namespace conus::viewer
