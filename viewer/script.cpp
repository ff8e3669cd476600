#include "script.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "actions.h"
#include "conus/core/error.h"

namespace conus::viewer {
namespace {

[[noreturn]] void fail(int line, const std::string& why) {
    throw Error(ErrorCode::InvalidArgument, "script line " + std::to_string(line) + ": " + why);
}

double number(const std::string& word, int line) {
    std::size_t used = 0;
    double value = 0;
    try {
        value = std::stod(word, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != word.size() || !std::isfinite(value)) fail(line, "'" + word + "' is not a number");
    return value;
}

}  // namespace

std::vector<ScriptCommand> parseScript(const std::string& text) {
    // Numeric argument counts; "zoom" also takes 3 (F at X Y).
    static const std::map<std::string, int> kNumbers = {{"zoom", 1}, {"wheel", 3}, {"pan", 2},  {"drag", 4},
                                                        {"mouse", 2}, {"inspect", 2}, {"wait", 1}, {"quit", 0},
                                                        {"orbit", 2}, {"dolly", 1}};
    std::vector<ScriptCommand> out;
    std::istringstream lines(text);
    int lineNumber = 0;
    for (std::string line; std::getline(lines, line);) {
        ++lineNumber;
        std::istringstream words(line);
        std::vector<std::string> w;
        for (std::string word; words >> word;) w.push_back(word);
        if (w.empty() || w[0][0] == '#') continue;
        ScriptCommand cmd;
        cmd.name = w[0];
        cmd.line = lineNumber;
        if (cmd.name == "key" || cmd.name == "screenshot") {
            if (w.size() != 2) fail(lineNumber, cmd.name + " takes one argument");
            cmd.text = w[1];
            if (cmd.name == "key" && !parseChord(cmd.text)) fail(lineNumber, "unknown key '" + cmd.text + "'");
            out.push_back(cmd);
            continue;
        }
        const auto it = kNumbers.find(cmd.name);
        if (it == kNumbers.end()) fail(lineNumber, "unknown command '" + cmd.name + "'");
        for (std::size_t k = 1; k < w.size(); ++k) {
            if (w[k] == "at" && (cmd.name == "zoom" || cmd.name == "wheel") && k == 2) continue;
            cmd.numbers.push_back(number(w[k], lineNumber));
        }
        const int n = static_cast<int>(cmd.numbers.size());
        const bool ok = n == it->second || (cmd.name == "zoom" && n == 3);
        if (!ok) fail(lineNumber, cmd.name + " takes " + std::to_string(it->second) + " numbers, got " + std::to_string(n));
        if (cmd.name == "dolly" && !(cmd.numbers[0] > 0)) fail(lineNumber, "dolly factor must be positive");
        if (cmd.name == "zoom" && !(cmd.numbers[0] > 0)) fail(lineNumber, "zoom factor must be positive");
        if (cmd.name == "wait" && (cmd.numbers[0] < 0 || cmd.numbers[0] > 1e6)) fail(lineNumber, "wait takes 0 .. 1e6 frames");
        out.push_back(cmd);
    }
    return out;
}

std::vector<ScriptCommand> readScript(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::Io, "cannot open script " + path);
    std::ostringstream text;
    text << in.rdbuf();
    return parseScript(text.str());
}

}  // namespace conus::viewer
