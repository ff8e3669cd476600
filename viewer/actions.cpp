#include "actions.h"

#include <algorithm>
#include <cctype>
#include <vector>

#include "conus/core/error.h"

namespace conus::viewer {
namespace {

struct Binding {
    const char* key;
    bool shift, ctrl;
    Action action;
    const char* help;  // empty: not listed (an alias of the line above)
};

// Shared by the viewer and the editor; the editor's own table is searched first.
const std::vector<Binding> kViewBindings = {
    {"H", false, false, Action::Help, "H          this help (over the view; again to close)"},
    {"F", false, false, Action::Fit, "F          fit the image to the window"},
    {"1", false, false, Action::SourceResolution, "1          source resolution (1 source pixel = 1 window pixel)"},
    {"+", false, false, Action::ZoomIn, "+ / -      zoom in / out about the window centre (wheel: about the cursor)"},
    {"=", false, false, Action::ZoomIn, ""},
    {"-", false, false, Action::ZoomOut, ""},
    {"Left", false, false, Action::PanLeft, "arrows     pan (drag with the left button too)"},
    {"Right", false, false, Action::PanRight, ""},
    {"Up", false, false, Action::PanUp, ""},
    {"Down", false, false, Action::PanDown, ""},
    {"C", false, false, Action::ModeReconstructed, "C          reconstructed frame (decoded from the CoNUS data)"},
    {"R", false, false, Action::ModeRaw, "R          raw CoNUS image, stretched"},
    {"U", false, false, Action::ModeUniform, "U          uniform image of the same pixel count (--uniform: the real one)"},
    {"W", false, false, Action::ModeWipe, "W          wipe: CoNUS left, uniform right (Shift-drag moves the split)"},
    {"D", false, false, Action::ModeDensity, "D          sampling density heat map (det J)"},
    {"Z", false, false, Action::ToggleDepth, "Z          a depth image's Z as a picture (near bright); again: colour"},
    {"G", false, false, Action::ToggleGrid, "G          CoNUS pixel grid overlay"},
    {"O", false, false, Action::ToggleOutlines, "O          focus outlines (r and 2r)"},
    {"E", true, false, Action::ExposureDown, "E / Shift-E exposure +/- 0.5 stop; 0 resets"},
    {"0", false, false, Action::ResetExposure, ""},
    {"L", false, false, Action::ToggleGamma, "L          linear output (no curve) / the sRGB display curve"},
    {"T", false, false, Action::NextToneMap, "T          next tone map for HDR values (--tonemap's choices)"},
    {"Tab", false, false, Action::NextFile, "Tab, PgDn  next file; Shift-Tab, PgUp previous"},
    {"PageDown", false, false, Action::NextFile, ""},
    {"Tab", true, false, Action::PreviousFile, ""},
    {"PageUp", false, false, Action::PreviousFile, ""},
    {"R", false, true, Action::Reload, "Ctrl-R, F5 reload the file from disk"},
    {"F5", false, false, Action::Reload, ""},
    {"I", false, false, Action::Inspect, "I          print the pixel under the cursor (also shown in the title)"},
    {"B", false, false, Action::ToggleStatusBar, "B          status bar: file, mode, zoom, the pixel under the cursor"},
    {"Q", false, false, Action::Quit, "Q, Esc     quit"},
    {"Escape", false, false, Action::Quit, ""},
};

const std::vector<Binding> kExposureUp = {{"E", false, false, Action::ExposureUp, ""}};

const std::vector<Binding> kEditBindings = {
    {"S", false, false, Action::SaveMap, "S          save the sampling map (<out>.map.exr)"},
    {"S", false, true, Action::EncodeImage, "Ctrl-S, E  encode the image through the map (<out>.conus.exr)"},
    {"E", false, false, Action::EncodeImage, ""},
    {"[", false, false, Action::StrengthDown, "[ / ]      brush strength down / up; Shift-wheel: brush radius"},
    {"]", false, false, Action::StrengthUp, ""},
    {"X", false, false, Action::ResetMap, "X          start again from the identity map"},
};

// The 3-D modes: searched before the viewer's table, whose display keys (R, C, Z, G, O, D, exposure,
// B, I, H, Q) still apply to the rendered frame; the file and navigation keys are not listed.
const std::vector<Binding> kSceneBindings = {
    {"Left", false, false, Action::OrbitLeft, "arrows     orbit the camera (left drag away from a focus too)"},
    {"Right", false, false, Action::OrbitRight, ""},
    {"Up", false, false, Action::OrbitUp, ""},
    {"Down", false, false, Action::OrbitDown, ""},
    {"+", false, false, Action::DollyIn, "+ / -      camera nearer / farther (wheel too)"},
    {"=", false, false, Action::DollyIn, ""},
    {"-", false, false, Action::DollyOut, ""},
    {"F", false, false, Action::HomeCamera, "F          the first camera again"},
    {"U", false, false, Action::ToggleConus, "U          CoNUS / conventional (identity map, or the --uniform asset)"},
    {"N", false, false, Action::AddFocus, "N          a new focus at the cursor (left drag on a focus moves it)"},
    {"X", false, false, Action::RemoveFocus, "X          remove the focus nearest the cursor"},
    {"[", false, false, Action::FocusSmaller, "[ / ]      foci smaller / larger"},
    {"]", false, false, Action::FocusLarger, ""},
    {"T", false, false, Action::NextLook, "T          volume: the next transfer function preset"},
};

// The viewer keys a 3-D mode keeps (listed after its own): the display of the rendered frame.
const Action kSceneKeeps[] = {Action::Help, Action::ModeReconstructed, Action::ModeRaw, Action::ModeDensity,
                              Action::ToggleDepth, Action::ToggleGrid, Action::ToggleOutlines, Action::ExposureUp,
                              Action::ExposureDown, Action::ResetExposure, Action::ToggleGamma, Action::Inspect,
                              Action::ToggleStatusBar, Action::Quit};

bool sceneKeeps(Action action) { return std::find(std::begin(kSceneKeeps), std::end(kSceneKeeps), action) != std::end(kSceneKeeps); }

const Binding* find(const std::vector<Binding>& table, const KeyChord& chord) {
    for (const auto& b : table)
        if (chord.key == b.key && chord.shift == b.shift && chord.ctrl == b.ctrl) return &b;
    return nullptr;
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
}

}  // namespace

std::optional<KeyChord> parseChord(const std::string& text) {
    KeyChord chord;
    std::string rest = text;
    for (;;) {
        const std::size_t plus = rest.find('+');
        if (plus == std::string::npos || plus + 1 >= rest.size()) break;  // "+" alone is the key
        const std::string modifier = lower(rest.substr(0, plus));
        if (modifier == "shift") chord.shift = true;
        else if (modifier == "ctrl" || modifier == "control") chord.ctrl = true;
        else return std::nullopt;
        rest = rest.substr(plus + 1);
    }
    static const char* kNamed[] = {"Tab", "F5", "Left", "Right", "Up", "Down", "PageUp", "PageDown", "Escape"};
    for (const char* name : kNamed)
        if (lower(rest) == lower(name)) {
            chord.key = name;
            return chord;
        }
    if (rest.size() != 1) return std::nullopt;
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(rest[0])));
    if (!std::isalnum(static_cast<unsigned char>(c)) && std::string("+-=[]").find(c) == std::string::npos)
        return std::nullopt;
    chord.key = std::string(1, c);
    return chord;
}

Action actionFor(const KeyChord& chord, KeyTable table) {
    if (table == KeyTable::Edit)
        if (const Binding* b = find(kEditBindings, chord)) return b->action;
    if (table == KeyTable::Scene) {
        if (const Binding* b = find(kSceneBindings, chord)) return b->action;
        const Binding* b = find(kViewBindings, chord);
        if (!b) b = find(kExposureUp, chord);
        return b && sceneKeeps(b->action) ? b->action : Action::None;
    }
    if (const Binding* b = find(kViewBindings, chord)) return b->action;
    if (const Binding* b = find(kExposureUp, chord)) return b->action;
    return Action::None;
}

std::string helpText(KeyTable table) {
    std::string text = table == KeyTable::Edit ? "conus-view --edit: paint with the left button (mass-spring brush, paper Fig. 8)\n"
                       : table == KeyTable::Scene ? "conus-view 3-D mode: the CoNUS frame rendered live (raw: the paper's focus-plus-context display)\n"
                                                  : "conus-view keys:\n";
    const auto add = [&](const std::vector<Binding>& bindings, bool keptOnly) {
        for (const auto& b : bindings)
            if (*b.help && (!keptOnly || sceneKeeps(b.action))) text += std::string("  ") + b.help + "\n";
    };
    if (table == KeyTable::Edit) add(kEditBindings, false);
    if (table == KeyTable::Scene) add(kSceneBindings, false);
    add(kViewBindings, table == KeyTable::Scene);
    return text;
}

}  // namespace conus::viewer
