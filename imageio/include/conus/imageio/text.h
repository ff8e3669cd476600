// Text drawn into images through OpenImageIO's render_text, in the font "DejaVuSans" (Debian:
// fonts-dejavu-core): the demo picture's print and the viewer's help, error and status panels.
// conus::Error(Io) when the font cannot be found or the text cannot be drawn.
#pragma once

#include <string>
#include <vector>

#include "conus/core/image.h"

namespace conus::imageio {

// Draws `text` in `color` (RGB) with its baseline-left at (x,y), `size` pixels tall, into the
// image's first channels (at most four: R, G, B and an opaque A).
void drawText(Image& image, int x, int y, int size, const std::string& text, const float color[3]);

// An inscription: `text`'s lines (split at '|') drawn white on black into a width x height RGB
// image, centred, each as large as fits in about three quarters of the width and of the height
// together (the engraved tablet's ink, codec/depth/relief.h). conus::Error(InvalidArgument) for
// empty text.
Image inscription(const std::string& text, int width, int height);

struct TextPanelStyle {
    int fontSize = 15;                          // pixels
    float text[4] = {1.0f, 1.0f, 1.0f, 1.0f};   // straight RGBA
    float panel[4] = {0.0f, 0.0f, 0.0f, 0.7f};  // the panel behind the text, straight RGBA
    int padding = 10;                           // pixels around the text
    int minWidth = 0;                           // the panel at least this wide (a status bar)
    int tabStop = 0;                            // pixels: text after a line's first '\t' starts there
};

// The lines on a panel sized to fit them: RGBA floats, top row first, straight alpha.
Image renderTextPanel(const std::vector<std::string>& lines, const TextPanelStyle& style);

// Width of `text` in pixels at `fontSize` (0 for empty text; an estimate without the font).
int textWidth(const std::string& text, int fontSize);

// `text` split at its newlines, then each line broken at spaces (or anywhere, for a word longer
// than a line) into lines at most maxWidth pixels wide at fontSize.
std::vector<std::string> wrapText(const std::string& text, int maxWidth, int fontSize);

}  // namespace conus::imageio
