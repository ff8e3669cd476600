#include "conus/codec/volume/transfer_function.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

struct Preset {
    const char* name;
    std::vector<TransferPoint> points;
};

// Values are normalized sample values; opacities per voxel length.
const std::vector<Preset>& presets() {
    static const std::vector<Preset> table = {
        // A linear grey ramp: density shows as brightness and opacity alike.
        {"grey", {{0.0f, {0, 0, 0, 0}}, {1.0f, {1, 1, 1, 0.25f}}}},
        // Soft tissue faint and warm, dense matter bright and nearly opaque (CT/MRI heads).
        {"bone",
         {{0.0f, {0, 0, 0, 0}},
          {0.25f, {0, 0, 0, 0}},
          {0.35f, {0.8f, 0.35f, 0.25f, 0.02f}},
          {0.6f, {0.95f, 0.8f, 0.6f, 0.2f}},
          {1.0f, {1, 1, 0.95f, 0.9f}}}},
        // Black body: dark red through orange to white, opacity rising with the value.
        {"fire",
         {{0.0f, {0, 0, 0, 0}},
          {0.3f, {0.5f, 0.02f, 0.0f, 0.02f}},
          {0.6f, {1.0f, 0.45f, 0.05f, 0.15f}},
          {1.0f, {1, 1, 0.9f, 0.6f}}}},
        // Two thin shells, blue and orange, for iso-surface-like structure (Marschner-Lobb).
        {"shells",
         {{0.0f, {0, 0, 0, 0}},
          {0.28f, {0, 0, 0, 0}},
          {0.33f, {0.2f, 0.4f, 1.0f, 0.5f}},
          {0.38f, {0, 0, 0, 0}},
          {0.65f, {0, 0, 0, 0}},
          {0.7f, {1.0f, 0.55f, 0.1f, 0.8f}},
          {0.75f, {0, 0, 0, 0}},
          {1.0f, {0, 0, 0, 0}}}},
    };
    return table;
}

std::string numbers(const TransferPoint& p) {
    return numberText(p.value) + " " + numberText(p.rgba.r) + " " + numberText(p.rgba.g) + " " + numberText(p.rgba.b) +
           " " + numberText(p.rgba.a);
}

}  // namespace

TransferFunction::TransferFunction(std::vector<TransferPoint> points) : m_points(std::move(points)) {
    if (m_points.size() < 2)
        throw Error(ErrorCode::InvalidArgument, "transfer function: " + std::to_string(m_points.size()) +
                                                    " points; it needs at least two");
    for (std::size_t i = 0; i < m_points.size(); ++i) {
        const TransferPoint& p = m_points[i];
        const float all[5] = {p.value, p.rgba.r, p.rgba.g, p.rgba.b, p.rgba.a};
        for (float v : all)
            if (!std::isfinite(v) || v < 0.0f || v > 1.0f)
                throw Error(ErrorCode::InvalidArgument, "transfer function: point " + std::to_string(i + 1) + " (" +
                                                            numbers(p) + ") has a number outside [0,1]");
        if (i > 0 && !(p.value > m_points[i - 1].value))
            throw Error(ErrorCode::InvalidArgument, "transfer function: point " + std::to_string(i + 1) + " (value " +
                                                        numberText(p.value) + ") does not follow value " +
                                                        numberText(m_points[i - 1].value) + "; values must increase");
    }
    m_table.resize(kTransferTableSize);
    std::size_t k = 0;
    for (int i = 0; i < kTransferTableSize; ++i) {
        const float s = static_cast<float>(i) / (kTransferTableSize - 1);
        if (s <= m_points.front().value) { m_table[i] = m_points.front().rgba; continue; }
        if (s >= m_points.back().value) { m_table[i] = m_points.back().rgba; continue; }
        while (m_points[k + 1].value < s) ++k;
        const TransferPoint &a = m_points[k], &b = m_points[k + 1];
        m_table[i] = glm::mix(a.rgba, b.rgba, (s - a.value) / (b.value - a.value));
    }
}

TransferFunction TransferFunction::preset(const std::string& name) {
    for (const Preset& p : presets())
        if (name == p.name) return TransferFunction(p.points);
    std::string names;
    for (const std::string& n : presetNames()) names += (names.empty() ? "" : ", ") + n;
    throw Error(ErrorCode::InvalidArgument, "transfer function: no preset '" + name + "' (presets: " + names + ")");
}

std::vector<std::string> TransferFunction::presetNames() {
    std::vector<std::string> names;
    for (const Preset& p : presets()) names.emplace_back(p.name);
    return names;
}

TransferFunction TransferFunction::parse(const std::string& text, const std::string& what) {
    std::vector<TransferPoint> points;
    std::istringstream lines(text);
    std::string line;
    for (int number = 1; std::getline(lines, line); ++number) {
        line = line.substr(0, line.find('#'));
        std::istringstream words(line);
        std::string first;
        if (!(words >> first)) continue;
        words.seekg(0);
        TransferPoint p;
        std::string extra;
        if (!(words >> p.value >> p.rgba.r >> p.rgba.g >> p.rgba.b >> p.rgba.a) || (words >> extra))
            throw Error(ErrorCode::InvalidArgument, "transfer function '" + what + "': line " + std::to_string(number) +
                                                        " is not five numbers \"value r g b a\"");
        points.push_back(p);
    }
    try {
        return TransferFunction(std::move(points));
    } catch (const Error& e) {
        throw Error(ErrorCode::InvalidArgument, "'" + what + "': " + e.what());
    }
}

TransferFunction TransferFunction::load(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw Error(ErrorCode::Io, "transfer function '" + path + "': no such file");
    if (std::filesystem::file_size(path, ec) > (1u << 20) || ec)
        throw Error(ErrorCode::LimitExceeded, "transfer function '" + path + "': larger than 1 MiB");
    std::ifstream in(path);
    if (!in) throw Error(ErrorCode::Io, "transfer function '" + path + "': cannot open it");
    std::ostringstream text;
    text << in.rdbuf();
    return parse(text.str(), path);
}

glm::vec4 TransferFunction::lookup(float s) const {
    const float f = std::clamp(s, 0.0f, 1.0f) * (kTransferTableSize - 1);
    const int i = std::min(static_cast<int>(f), kTransferTableSize - 2);
    return glm::mix(m_table[i], m_table[i + 1], f - static_cast<float>(i));
}

}  // namespace conus::codec
