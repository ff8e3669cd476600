// Image files at the viewer's edge (PNG screenshots, the --edit source image) through
// OpenImageIO; the only file of viewer/ that includes it. CoNUS files go through conus::format.
#pragma once

#include <string>
#include <vector>

#include "conus/format/image.h"

namespace conus::viewer {

// Any image OpenImageIO reads, as float (8/16-bit values scaled to [0,1]); conus::Error(Io) when
// it cannot be read, LimitExceeded beyond the library's image limits.
format::Image readImage(const std::string& path);

// The first three channels (or one grey channel) as an 8-bit PNG/JPEG, or float EXR/TIFF by
// extension; values are clamped to [0,1] for 8-bit formats. conus::Error(Io) on failure.
void writeImage(const std::string& path, const format::Image& image);

// Text for the window's overlays, rasterized by OpenImageIO's render_text in the font "DejaVuSans"
// (Debian: fonts-dejavu-core).
struct TextPanelStyle {
    int fontSize = 15;                          // pixels
    float text[4] = {1.0f, 1.0f, 1.0f, 1.0f};   // straight RGBA
    float panel[4] = {0.0f, 0.0f, 0.0f, 0.7f};  // the panel behind the text, straight RGBA
    int padding = 10;                           // pixels around the text
    int minWidth = 0;                           // the panel at least this wide (a status bar)
    int tabStop = 0;                            // pixels: text after a line's first '\t' starts there
};

// The lines on a panel sized to fit them: RGBA floats, top row first, straight alpha.
// conus::Error(Io) when the font cannot be found or the text cannot be drawn.
format::Image renderTextPanel(const std::vector<std::string>& lines, const TextPanelStyle& style);

// Width of `text` in pixels at `fontSize` (0 for empty text; an estimate without the font).
int textWidth(const std::string& text, int fontSize);

// `text` split at its newlines, then each line broken at spaces (or anywhere, for a word longer
// than a line) into lines at most maxWidth pixels wide at fontSize.
std::vector<std::string> wrapText(const std::string& text, int maxWidth, int fontSize);

}  // namespace conus::viewer
