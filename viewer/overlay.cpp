#include "overlay.h"

#include <algorithm>
#include <sstream>
#include <vector>

#include "actions.h"
#include "conus/imageio/text.h"

namespace conus::viewer {

Image helpPanel(KeyTable table) {
    // helpText's lines are "  KEYS       what they do": the keys in a column of their own.
    constexpr std::size_t kKeyColumn = 13;
    std::vector<std::string> lines;
    std::istringstream text(helpText(table));
    for (std::string line; std::getline(text, line);) {
        if (line.rfind("  ", 0) == 0 && line.size() > kKeyColumn) {
            std::string keys = line.substr(2, kKeyColumn - 2);
            keys.erase(keys.find_last_not_of(' ') + 1);
            std::string what = line.substr(kKeyColumn);
            what.erase(0, what.find_first_not_of(' ') == std::string::npos ? what.size() : what.find_first_not_of(' '));
            lines.push_back(what.empty() ? keys : keys + "\t" + what);
        } else {
            lines.push_back(line);
        }
    }
    lines.push_back("H\tclose this help");
    imageio::TextPanelStyle style;
    style.fontSize = 15;
    style.tabStop = 110;
    style.panel[3] = 0.72f;
    return imageio::renderTextPanel(lines, style);
}

Image errorPanel(const std::string& fileName, const std::string& error, int windowWidth) {
    imageio::TextPanelStyle style;
    style.fontSize = 16;
    style.panel[3] = 0.55f;
    const int maxWidth = std::max(64, windowWidth - 2 * kOverlayMargin - 2 * style.padding);
    std::vector<std::string> lines = imageio::wrapText("Cannot open " + fileName + ": not a valid CoNUS file", maxWidth, style.fontSize);
    for (const std::string& line : imageio::wrapText(error, maxWidth, style.fontSize)) lines.push_back(line);
    lines.push_back("");
    for (const std::string& line : imageio::wrapText("Tab: next file, Ctrl-R: reload, Q: quit", maxWidth, style.fontSize))
        lines.push_back(line);
    return imageio::renderTextPanel(lines, style);
}

Image statusPanel(const std::string& text, int windowWidth) {
    imageio::TextPanelStyle style;
    style.fontSize = 13;
    style.padding = 4;
    style.panel[3] = 0.6f;
    style.minWidth = std::max(1, windowWidth);
    return imageio::renderTextPanel({text}, style);
}

}  // namespace conus::viewer
