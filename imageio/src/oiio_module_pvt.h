// Private: the half of conus_imageio that calls OpenImageIO, built as the module
// libconus_imageio_oiio (loaded on first use; core/plugin.h says why) and called through one table.
// The public functions of image_file.h and text.h forward to it (image_api.cpp). Both sides are
// built together, so the table may carry C++ types.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "conus/imageio/image_file.h"
#include "conus/imageio/text.h"

namespace conus::imageio {

namespace oiio {
// The implementations (image_read.cpp, image_write.cpp, image_colour.cpp, text.cpp); same meaning
// as the public functions.
ImageFile readImageFile(const std::string& path, const ReadOptions& options);
void writeImageFile(const std::string& path, const Image& image, const WriteOptions& options);
void checkImageOutput(const std::string& path, const WriteOptions& options);
std::string sampleTypesOf(const std::string& path);
void linearize(Image& image);
Image displayEncoded(const Image& image);
void repairNonFinite(Image& image, NonFiniteRepair repair, const std::string& shown);  // repair.cpp
void drawText(Image& image, int x, int y, int size, const std::string& text, const float color[3]);
Image renderTextPanel(const std::vector<std::string>& lines, const TextPanelStyle& style);
int textWidth(const std::string& text, int fontSize);
std::vector<std::string> wrapText(const std::string& text, int maxWidth, int fontSize);
}  // namespace oiio

struct OiioFunctions {
    decltype(&oiio::readImageFile) readImageFile;
    decltype(&oiio::writeImageFile) writeImageFile;
    decltype(&oiio::checkImageOutput) checkImageOutput;
    decltype(&oiio::sampleTypesOf) sampleTypesOf;
    decltype(&oiio::linearize) linearize;
    decltype(&oiio::displayEncoded) displayEncoded;
    decltype(&oiio::repairNonFinite) repairNonFinite;
    decltype(&oiio::drawText) drawText;
    decltype(&oiio::renderTextPanel) renderTextPanel;
    decltype(&oiio::textWidth) textWidth;
    decltype(&oiio::wrapText) wrapText;
};

// The table, from the module loaded on first use (oiio_load_module.cpp) or, in a static build,
// linked in (oiio_load_static.cpp).
const OiioFunctions& oiioFunctions();

}  // namespace conus::imageio

// The module's one exported symbol (oiio_module.cpp).
extern "C" const conus::imageio::OiioFunctions* conusImageioOiio();
