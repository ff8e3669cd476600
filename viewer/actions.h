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
    ToggleDepth,        // Z: a depth image's Z channel as a picture (the inferno ramp, near bright)
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
    // 3-D modes (--mesh, --volume, --relief, --reflection)
    OrbitLeft, OrbitRight, OrbitUp, OrbitDown,  // arrows
    DollyIn, DollyOut,  // + / -
    HomeCamera,         // F
    ToggleConus,        // U: CoNUS (the foci's map, or the CoNUS asset) / conventional
    AddFocus,           // N: a focus at the cursor
    RemoveFocus,        // X: the focus nearest the cursor
    FocusSmaller, FocusLarger,  // [ ]
    NextLook,           // T: a volume's next transfer function
};

// Which key table is in use: the file viewer's, the map editor's (--edit), a 3-D mode's.
enum class KeyTable { View, Edit, Scene };

struct KeyChord {
    std::string key;  // a key name (above)
    bool shift = false, ctrl = false;
};

// "G", "shift+E", "ctrl+R", "Ctrl+Shift+Tab" -> chord; nullopt for an unknown key name.
std::optional<KeyChord> parseChord(const std::string& text);

// The action of a chord in `table` (the editor's and the 3-D modes' keys come first, then the
// viewer's they keep).
Action actionFor(const KeyChord& chord, KeyTable table);

// One line per key of the table in use.
std::string helpText(KeyTable table);

}  // namespace conus::viewer
