#include "image_io.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>

#include <cmath>
#include <sstream>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "conus/format/error.h"

namespace conus::viewer {

format::Image readImage(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(ErrorCode::Io, "cannot read image " + path + ": " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.width > format::kMaxImageSide ||
        spec.height > format::kMaxImageSide ||
        std::int64_t(spec.width) * spec.height > format::kMaxImagePixels)
        throw Error(ErrorCode::LimitExceeded, path + ": image size " + std::to_string(spec.width) + "x" +
                                                  std::to_string(spec.height) + " is outside the supported range");
    std::vector<std::string> names;
    for (int c = 0; c < spec.nchannels; ++c) names.push_back(spec.channel_name(c));
    format::Image image = format::makeImage(spec.width, spec.height, names);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
        throw Error(ErrorCode::Io, "cannot read image " + path + ": " + in->geterror());
    return image;
}

void writeImage(const std::string& path, const format::Image& image) {
    const int channels = image.channelCount() >= 3 ? 3 : 1;
    std::vector<float> pixels(static_cast<std::size_t>(image.width) * image.height * channels);
    for (std::size_t i = 0; i < static_cast<std::size_t>(image.width) * image.height; ++i)
        for (int c = 0; c < channels; ++c) pixels[i * channels + c] = image.pixels[i * image.channels.size() + c];
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw Error(ErrorCode::Io, "cannot write " + path + ": " + OIIO::geterror());
    const std::string ext = path.substr(path.find_last_of('.') + 1);
    const bool eightBit = ext != "exr" && ext != "EXR" && ext != "tif" && ext != "tiff";
    OIIO::ImageSpec spec(image.width, image.height, channels, eightBit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    if (eightBit)
        for (float& v : pixels) v = std::clamp(v, 0.0f, 1.0f);
    // A temporary file beside the destination, renamed into place: never a half-written screenshot.
    const std::filesystem::path target(path);
    const std::filesystem::path temp =
        target.parent_path() / ("." + target.stem().string() + ".tmp-" + std::to_string(::getpid()) + target.extension().string());
    if (!out->open(temp.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close()) {
        const std::string reason = out->geterror();
        std::error_code ignored;
        std::filesystem::remove(temp, ignored);
        throw Error(ErrorCode::Io, "cannot write " + path + ": " + reason);
    }
    std::error_code ec;
    std::filesystem::rename(temp, target, ec);
    if (ec) {
        std::filesystem::remove(temp, ec);
        throw Error(ErrorCode::Io, "cannot write " + path + ": cannot rename the finished file into place");
    }
}

constexpr const char* kFont = "DejaVuSans";

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

format::Image renderTextPanel(const std::vector<std::string>& lines, const TextPanelStyle& style) {
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
    width = std::clamp(std::max(width + 2 * style.padding, style.minWidth), 1, format::kMaxImageSide);
    const int height = std::clamp(static_cast<int>(lines.size()) * lineHeight + 2 * style.padding, 1, format::kMaxImageSide);
    format::Image panel = format::makeImage(width, height, {"R", "G", "B", "A"});
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

}  // namespace conus::viewer
