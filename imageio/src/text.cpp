// Text through OpenImageIO's render_text (in the module libconus_imageio_oiio, oiio_module_pvt.h).
#include "conus/imageio/text.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "conus/core/error.h"
#include "oiio_module_pvt.h"

namespace conus::imageio::oiio {

constexpr const char* kFont = "DejaVuSans";

void drawText(Image& image, int x, int y, int size, const std::string& text, const float color[3]) {
    // Text wholly outside the image is not drawn: OpenImageIO 2.4's render_text fails an assertion
    // (ends the process) on text entirely above or below the image.
    if (const OIIO::ROI box = OIIO::ImageBufAlgo::text_size(text, size, kFont); box.defined())
        if (y + box.yend <= 0 || y + box.ybegin >= image.height || x + box.xend <= 0 || x + box.xbegin >= image.width) return;
    OIIO::ImageSpec spec(image.width, image.height, image.channelCount(), OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf buffer(spec, image.pixels.data());  // wraps our pixels: drawn in place
    const float rgba[4] = {color[0], color[1], color[2], 1.0f};
    if (!OIIO::ImageBufAlgo::render_text(buffer, x, y, text, size, kFont, OIIO::cspan<float>(rgba, std::min(4, image.channelCount()))))
        throw Error(ErrorCode::Io, std::string("cannot draw text in the font ") + kFont + " (package fonts-dejavu-core): " +
                                       buffer.geterror());
}

int textWidth(const std::string& text, int fontSize) {
    if (text.empty()) return 0;
    const OIIO::ROI roi = OIIO::ImageBufAlgo::text_size(text, fontSize, kFont);
    if (!roi.defined()) return static_cast<int>(std::lround(0.6 * fontSize * static_cast<double>(text.size())));
    return roi.xend;  // from the pen's start (x 0) to the right edge of the last glyph
}

std::vector<std::string> wrapText(const std::string& text, int maxWidth, int fontSize) {
    std::vector<std::string> out;
    std::istringstream paragraphs(text);
    std::string paragraph;
    while (std::getline(paragraphs, paragraph)) {
        std::string line;
        std::istringstream words(paragraph);
        std::string word;
        while (words >> word) {
            const std::string candidate = line.empty() ? word : line + " " + word;
            if (textWidth(candidate, fontSize) <= maxWidth) {
                line = candidate;
                continue;
            }
            if (!line.empty()) out.push_back(line);
            line = word;
            // A word wider than a line (a long path): broken wherever it must be.
            while (line.size() > 1 && textWidth(line, fontSize) > maxWidth) {
                std::size_t n = line.size() - 1;
                while (n > 1 && textWidth(line.substr(0, n), fontSize) > maxWidth) --n;
                out.push_back(line.substr(0, n));
                line = line.substr(n);
            }
        }
        out.push_back(line);  // an empty paragraph stays an empty line
    }
    return out;
}

Image renderTextPanel(const std::vector<std::string>& lines, const TextPanelStyle& style) {
    const int lineHeight = static_cast<int>(std::lround(style.fontSize * 1.3));
    int width = 0;
    // A line "key\tdescription" is two columns, the second at style.tabStop.
    const auto columns = [&](const std::string& line) {
        const std::size_t tab = line.find('\t');
        return tab == std::string::npos ? std::pair<std::string, std::string>{line, ""}
                                        : std::pair<std::string, std::string>{line.substr(0, tab), line.substr(tab + 1)};
    };
    for (const std::string& line : lines) {
        const auto [left, right] = columns(line);
        width = std::max(width, right.empty() ? textWidth(left, style.fontSize) : style.tabStop + textWidth(right, style.fontSize));
    }
    width = std::clamp(std::max(width + 2 * style.padding, style.minWidth), 1, kMaxImageSide);
    const int height = std::clamp(static_cast<int>(lines.size()) * lineHeight + 2 * style.padding, 1, kMaxImageSide);
    Image panel = makeImage(width, height, {"R", "G", "B", "A"});
    for (std::size_t i = 0; i < panel.pixels.size(); ++i) panel.pixels[i] = style.panel[i % 4];
    OIIO::ImageBuf buffer(OIIO::ImageSpec(width, height, 4, OIIO::TypeDesc::FLOAT), panel.pixels.data());
    // render_text's y is the baseline: the ascent (about 0.8 of the size) below each line's top.
    const int ascent = static_cast<int>(std::lround(style.fontSize * 1.0));
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const int y = style.padding + static_cast<int>(i) * lineHeight + ascent;
        const auto [left, right] = columns(lines[i]);
        bool ok = true;
        if (!left.empty())
            ok = OIIO::ImageBufAlgo::render_text(buffer, style.padding, y, left, style.fontSize, kFont, OIIO::cspan<float>(style.text, 4));
        if (ok && !right.empty())
            ok = OIIO::ImageBufAlgo::render_text(buffer, style.padding + style.tabStop, y, right, style.fontSize, kFont,
                                                 OIIO::cspan<float>(style.text, 4));
        if (!ok)
            throw Error(ErrorCode::Io, std::string("cannot draw text in the font ") + kFont + " (package fonts-dejavu-core): " +
                                           buffer.geterror());
    }
    return panel;
}

}  // namespace conus::imageio::oiio
