// The public functions of image_file.h and text.h. Those that need OpenImageIO forward to its
// module (oiio_module.h), so a process that never touches an image file never loads it.
#include "conus/imageio/image_file.h"
#include "conus/imageio/text.h"
#include "oiio_module.h"

namespace conus::imageio {

ImageFile readImageFile(const std::string& path, const ReadOptions& options) {
    return oiioFunctions().readImageFile(path, options);
}

void writeImageFile(const std::string& path, const Image& image, const WriteOptions& options) {
    oiioFunctions().writeImageFile(path, image, options);
}

void checkImageOutput(const std::string& path, const WriteOptions& options) { oiioFunctions().checkImageOutput(path, options); }

std::string sampleTypesOf(const std::string& path) { return oiioFunctions().sampleTypesOf(path); }

void linearize(Image& image) { oiioFunctions().linearize(image); }

Image displayEncoded(const Image& image) { return oiioFunctions().displayEncoded(image); }

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

}  // namespace conus::imageio
