#include "overlay.h"

#include <algorithm>
#include <sstream>
#include <vector>

#include "actions.h"
#include "image_io.h"

namespace conus::viewer {

format::Image helpPanel(bool editing) {
    // helpText's lines are "  KEYS       what they do": the keys in a column of their own.
    constexpr std::size_t kKeyColumn = 13;
    std::vector<std::string> lines;
    std::istringstream text(helpText(editing));
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
    TextPanelStyle style;
    style.fontSize = 15;
    style.tabStop = 110;
    style.panel[3] = 0.72f;
    return renderTextPanel(lines, style);
}

format::Image errorPanel(const std::string& fileName, const std::string& error, int windowWidth) {
    TextPanelStyle style;
    style.fontSize = 16;
    style.panel[3] = 0.55f;
    const int maxWidth = std::max(64, windowWidth - 2 * kOverlayMargin - 2 * style.padding);
    std::vector<std::string> lines = wrapText("Cannot open " + fileName + ": not a valid CoNUS file", maxWidth, style.fontSize);
    for (const std::string& line : wrapText(error, maxWidth, style.fontSize)) lines.push_back(line);
    lines.push_back("");
    for (const std::string& line : wrapText("Tab: next file, Ctrl-R: reload, Q: quit", maxWidth, style.fontSize))
        lines.push_back(line);
    return renderTextPanel(lines, style);
}

format::Image statusPanel(const std::string& text, int windowWidth) {
    TextPanelStyle style;
    style.fontSize = 13;
    style.padding = 4;
    style.panel[3] = 0.6f;
    style.minWidth = std::max(1, windowWidth);
    return renderTextPanel({text}, style);
}

}  // namespace conus::viewer
