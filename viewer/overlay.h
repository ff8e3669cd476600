// What conus-view draws as text over the frame: the help panel (H), the error of a file that could
// not be opened, and the status bar (B). Rasterized by imageio's renderTextPanel (OpenImageIO),
// uploaded once per change into a ViewRenderer overlay slot and drawn over every frame.
#pragma once

#include <string>

#include "actions.h"
#include "conus/core/image.h"

namespace conus::viewer {

inline constexpr int kHelpSlot = 0, kErrorSlot = 1, kStatusSlot = 2;  // ViewRenderer overlay slots
inline constexpr int kSceneSlot = 3;  // a 3-D mode's frame, drawn 1:1 under the panels (drawing.cpp)
inline constexpr int kOverlayMargin = 16;  // window pixels between the panels and the window's edge

// The key list of helpText(table) on a semi-transparent dark panel, white text.
Image helpPanel(KeyTable table);
// "Cannot open <file>" and the reason, wrapped to fit a window `windowWidth` pixels wide.
Image errorPanel(const std::string& fileName, const std::string& error, int windowWidth);
// One line across the window's width (file, mode, zoom, the pixel under the cursor).
Image statusPanel(const std::string& text, int windowWidth);

}  // namespace conus::viewer
