// The public functions of image_file.h and text.h. Those that need OpenImageIO forward to its
// module (oiio_module_pvt.h), so a process that never touches an image file never loads it.
#include <algorithm>
#include <sstream>

#include "conus/core/error.h"
#include "conus/imageio/image_file.h"
#include "conus/imageio/text.h"
#include "display_encode_pvt.h"
#include "oiio_module_pvt.h"
#include "png_direct_pvt.h"

namespace conus::imageio {

// Plain PNG files (most photographs and renders handed to `conus encode`) need no OpenImageIO.
ImageFile readImageFile(const std::string& path, const ReadOptions& options) {
    if (std::optional<ImageFile> direct = readPngDirect(path, options)) return std::move(*direct);
    return oiioFunctions().readImageFile(path, options);
}

void writeImageFile(const std::string& path, const Image& image, const WriteOptions& options) {
    oiioFunctions().writeImageFile(path, image, options);
}

void checkImageOutput(const std::string& path, const WriteOptions& options) { oiioFunctions().checkImageOutput(path, options); }

std::string sampleTypesOf(const std::string& path) { return oiioFunctions().sampleTypesOf(path); }

void linearize(Image& image) { oiioFunctions().linearize(image); }

// Without alpha (a photograph) there is nothing to divide out and the sRGB curve needs no
// OpenImageIO (display_encode_pvt.h): a `conus encode` of a PNG then never loads it.
Image displayEncoded(const Image& image) {
    if (image.channelIndex("A") < 0) return displayEncodedOpaque(image);
    return oiioFunctions().displayEncoded(image);
}

void repairNonFinite(Image& image, NonFiniteRepair repair) { oiioFunctions().repairNonFinite(image, repair, "an image"); }

void drawText(Image& image, int x, int y, int size, const std::string& text, const float color[3]) {
    oiioFunctions().drawText(image, x, y, size, text, color);
}

Image renderTextPanel(const std::vector<std::string>& lines, const TextPanelStyle& style) {
    return oiioFunctions().renderTextPanel(lines, style);
}

int textWidth(const std::string& text, int fontSize) { return oiioFunctions().textWidth(text, fontSize); }

std::vector<std::string> wrapText(const std::string& text, int maxWidth, int fontSize) {
    return oiioFunctions().wrapText(text, maxWidth, fontSize);
}

// Needs no OpenImageIO of its own: it draws through drawText and textWidth.
Image inscription(const std::string& text, int width, int height) {
    std::vector<std::string> lines;
    std::stringstream in(text);
    for (std::string line; std::getline(in, line, '|');)
        if (!line.empty()) lines.push_back(line);
    if (lines.empty()) throw Error(ErrorCode::InvalidArgument, "an inscription needs some text");
    Image ink = makeImage(width, height, {"R", "G", "B"});
    const int usable = static_cast<int>(0.72 * width);
    int fontSize = std::max(4, static_cast<int>(0.62 * height / lines.size()));
    for (const std::string& line : lines)
        if (const int w = textWidth(line, fontSize); w > usable) fontSize = std::max(4, fontSize * usable / w);
    const float white[3] = {1.0f, 1.0f, 1.0f};
    // Baselines spaced 1.25 font sizes apart, the block centred (a cap is about 0.7 of the size).
    const double lineHeight = 1.25 * fontSize;
    const double first = 0.5 * height - 0.5 * lineHeight * (lines.size() - 1) + 0.35 * fontSize;
    for (std::size_t i = 0; i < lines.size(); ++i)
        drawText(ink, (width - textWidth(lines[i], fontSize)) / 2, static_cast<int>(first + lineHeight * i), fontSize,
                 lines[i], white);
    return ink;
}

}  // namespace conus::imageio
