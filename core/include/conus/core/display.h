// From linear light to a display: exposure, an optional tone map for values above 1, and the
// display's transfer curve. One definition for every place that shows linear data: `conus decode`
// to PNG/JPEG (imageio applies exposure and tone map; OpenImageIO encodes sRGB) and the viewer
// (its CPU path calls these; its shader mirrors them: `display` in renderers/shaders/view_frame.frag.glsl).
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <string_view>
#include <utility>

#include "conus/core/enum_names.h"

namespace conus {

enum class ToneMap {
    None,      // values above 1 clip at the display
    Reinhard,  // x / (1 + x) per channel: every value fits, highlights compress
    Aces,      // Narkowicz's fit of the ACES filmic curve per channel: contrasty, saturates to white
};

constexpr auto enumNameTable(ToneMap) {
    return makeEnumNameTable<ToneMap>(
        "tone map", {{ToneMap::None, "none"}, {ToneMap::Reinhard, "reinhard"}, {ToneMap::Aces, "aces"}});
}

struct DisplayOptions {
    double exposure = 0.0;  // stops: values are multiplied by 2^exposure first
    ToneMap toneMap = ToneMap::None;
};

// The heat-map ramp of density pictures (after matplotlib's "inferno", six display-encoded sRGB
// stops from dark to bright): cli's pictures and the viewer's density mode (its shader gets these
// values injected) draw with it.
inline constexpr std::array<std::array<float, 3>, 6> kInfernoRamp{{{0.001f, 0.000f, 0.014f},
                                                                   {0.258f, 0.039f, 0.406f},
                                                                   {0.578f, 0.148f, 0.404f},
                                                                   {0.865f, 0.317f, 0.226f},
                                                                   {0.988f, 0.645f, 0.040f},
                                                                   {0.988f, 0.998f, 0.645f}}};

// Exposure then tone map, for a linear colour value (not alpha, not data). NaN stays NaN.
inline float exposeAndToneMap(float linear, float gain, ToneMap toneMap) {
    const float x = linear * gain;
    switch (toneMap) {
        case ToneMap::None: return x;
        case ToneMap::Reinhard: return x > 0.0f ? x / (1.0f + x) : 0.0f;
        case ToneMap::Aces: {
            const float v = x > 0.0f ? x : 0.0f;
            const float y = (v * (2.51f * v + 0.03f)) / (v * (2.43f * v + 0.59f) + 0.14f);
            return y < 1.0f ? y : 1.0f;
        }
    }
    return x;
}

// The sRGB transfer curve (IEC 61966-2-1) from linear [0,1] to display [0,1], clamped: what a
// display shows. Files are encoded by OpenImageIO instead; this serves the viewer's CPU path.
inline float linearToSrgbDisplay(float linear) {
    const float x = linear > 0.0f ? (linear < 1.0f ? linear : 1.0f) : 0.0f;
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

// The sRGB curve's inverse, from display [0,1] to linear light (IEC 61966-2-1), computed in double
// and rounded once: colours drawn as a display shows them (a procedural ramp) made linear.
inline float srgbDisplayToLinear(float display) {
    const double x = display;
    return static_cast<float>(x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4));
}

}  // namespace conus
