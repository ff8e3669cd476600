// --script files: commands that drive the real window, one per line, for tests and demos. Each
// command runs in its own frame, in order; the viewer exits after the last one. Blank lines and
// lines starting with '#' are skipped. Coordinates are window pixels (x right, y down).
//
//   zoom F [at X Y]        multiply the zoom by F about (X,Y) (default: the window centre)
//   wheel N at X Y         N wheel notches at (X,Y) (Shift-wheel in the editor: brush radius)
//   pan DX DY              move the image by (DX,DY) pixels
//   drag X0 Y0 X1 Y1       left-button drag (pans; paints in the editor)
//   mouse X Y              move the cursor (the title shows the pixel under it)
//   key CHORD              press a key, e.g. `key G`, `key shift+E`, `key ctrl+R`
//   inspect X Y            print the pixel inspector's line for (X,Y)
//   wait N                 N frames (the editor's solver steps meanwhile)
//   screenshot PATH        save the window's frame (PNG)
//   orbit DYAW DPITCH      3-D modes: turn the camera about the scene (degrees)
//   dolly F                3-D modes: multiply the camera's distance by F
// In the 3-D modes a `drag` that starts on a focus moves it; elsewhere it orbits.
//   quit                   stop here
#pragma once

#include <string>
#include <vector>

namespace conus::viewer {

struct ScriptCommand {
    std::string name;             // zoom, wheel, pan, drag, mouse, key, inspect, wait, screenshot, quit, orbit, dolly
    std::vector<double> numbers;  // numeric arguments in order ("at" dropped)
    std::string text;             // key chord or path
    int line = 0;
};

// Throws conus::Error(InvalidArgument) "script line N: ..." for an unknown command or bad arguments.
std::vector<ScriptCommand> parseScript(const std::string& text);
// Reads and parses a file; conus::Error(Io) when it cannot be read.
std::vector<ScriptCommand> readScript(const std::string& path);

}  // namespace conus::viewer
