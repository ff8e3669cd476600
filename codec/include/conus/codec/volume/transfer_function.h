// The 1-D transfer function of the volume renderers: a sample's value, normalized to [0,1] over
// the render's value range, to an emitted colour and an opacity. Given as points (value -> RGBA,
// linear between them, the end points' colours held beyond them), it is tabulated once at
// kTransferTableSize evenly spaced values; both renderers read that one table, linearly between
// entries (the CPU by hand, the GPU as a 1-D texture with GL_LINEAR), so they agree exactly.
//
// Opacity A is per unit of distance equal to the volume's smallest spacing (one voxel); a
// renderer stepping s voxels corrects it to 1 - (1 - A)^s. Colours are linear light.
//
// The text format (`--tf file`): one point a line, "value r g b a", numbers in [0,1], values
// strictly increasing; '#' starts a comment; blank lines are skipped; at least two points.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace conus::codec {

inline constexpr int kTransferTableSize = 256;

struct TransferPoint {
    float value = 0;  // normalized sample value in [0,1]
    glm::vec4 rgba{0.0f};
};

class TransferFunction {
public:
    // Throws conus::Error(InvalidArgument) for fewer than two points, a number outside [0,1] or
    // not finite, or values not strictly increasing.
    explicit TransferFunction(std::vector<TransferPoint> points);

    // The preset a volume gets when none is named (`render volume` and the viewer alike).
    static constexpr const char* kDefaultPreset = "bone";
    // The presets by name (presetNames()); an unknown name throws InvalidArgument listing them.
    static TransferFunction preset(const std::string& name);
    static std::vector<std::string> presetNames();
    // The text format above; `what` names the source in messages (a path). Errors are
    // InvalidArgument naming the line.
    static TransferFunction parse(const std::string& text, const std::string& what);
    // Reads a file in the text format (Io when it cannot be read; at most 1 MiB).
    static TransferFunction load(const std::string& path);

    const std::vector<TransferPoint>& points() const { return m_points; }
    // kTransferTableSize entries, entry i at normalized value i / (kTransferTableSize - 1).
    const std::vector<glm::vec4>& table() const { return m_table; }
    // The table read linearly at normalized value s (clamped to [0,1]).
    glm::vec4 lookup(float s) const;

private:
    std::vector<TransferPoint> m_points;
    std::vector<glm::vec4> m_table;
};

}  // namespace conus::codec
