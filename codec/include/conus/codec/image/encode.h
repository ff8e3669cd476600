// CPU reference encoder: renders a CoNUS image from a conventional image through a sampling map.
// A CoNUS pixel centred at distorted p_d takes the source at undistorted SM^-1(p_d), filtered over
// the pixel's footprint in the source: the footprint follows the local Jacobian of the map, so
// there is no aliasing where the map compresses and no blur where it magnifies.
//
// Shared rules: sources are float images with any channels (alpha and Z preserved as channels);
// threads = 0 uses every core; sizes are checked (conus::Error InvalidArgument / LimitExceeded).
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/enum_names.h"
#include "conus/core/error.h"
#include "conus/core/image.h"
#include "conus/core/limits.h"

namespace conus::codec {

// The encoder's footprint rule, shared with its GLSL twin (renderers inject these values).
// A CoNUS pixel's footprint in the source is the parallelogram spanned by the inverse Jacobian's
// columns a and b (one CoNUS pixel each way). Its filter, in CoNUS pixel units (s,t), is the unit
// box convolved with a Gaussian along the footprint's major axis whose standard deviation grows
// with the anisotropy and with how far the major axis outspans the uniform image's pixel:
// kEncodeAnisotropicSigma * min(1 - kEncodeBoxAnisotropy * minor / major, 1 - uniform / major) CoNUS
// pixels where that is positive, cut at kEncodeGaussianReach standard deviations; `uniform` is the
// spacing of the uniform image of the same pixel count, sqrt(source area / CoNUS area) source pixels.
// A footprint up to kEncodeBoxAnisotropy : 1 keeps the plain box (the exact area average; a pixel
// grid with different ratios per axis is one); a long thin one is low-passed along its length, where
// a box's side lobes alias into a radial comb once the decoder magnifies it
// (tests/codec/image/comb_test.cpp measures it). A major axis no longer than the uniform pixel
// also keeps the box: it aliases no more than the uniform image's own box filter does (the inner
// ring of a focus, dense both ways; the Gaussian there cost 0.7 dB for nothing, bench/notes/2026-11-24-comb-at-focus-rims.md).
// The pyramid level is the first where the minor axis is at most kEncodeMaxTaps texels and the
// filter's extent along a and b at most kEncodeMaxAxisTaps: taps are at most a texel apart along
// each edge, so a long axis takes many taps instead of being truncated (a longer one moves up a
// level, blurring more, never aliasing). kEncodeTapTolerance keeps integer ratios exact despite
// float map nodes (a footprint of 4.0005 source pixels is still 4 taps).
inline constexpr int kEncodeMaxTaps = 4;
inline constexpr int kEncodeMaxAxisTaps = 64;
inline constexpr double kEncodeTapTolerance = 1e-3;
inline constexpr double kEncodeAnisotropicSigma = 1.5;
inline constexpr double kEncodeGaussianReach = 2.5;
inline constexpr double kEncodeBoxAnisotropy = 1.5;

// The rule above for one footprint whose edges are a and b (level-0 source pixels per CoNUS pixel),
// the uniform pixel `uniform` source pixels wide (uniformSpacing): the continuous pyramid level (its
// floor and the next level are blended) and the filter's extent along a and along b in CoNUS
// pixels. The GPU encoder sizes its tiles' margins with it.
struct FootprintPlan {
    double level = 0;
    glm::dvec2 extent{1.0, 1.0};
    // How far the filter low-passes the long axis: its extent beyond the unit box, in CoNUS
    // pixels, at most 1; 0 where the box was kept (the fit holds such pixels, fit.h).
    float lowPassShare() const { return static_cast<float>(std::clamp(std::max(extent.x, extent.y) - 1.0, 0.0, 1.0)); }
};
FootprintPlan planFootprint(glm::dvec2 a, glm::dvec2 b, double uniform);
// sqrt(sourceWidth * sourceHeight / (width * height)): the uniform image's pixel, in source pixels.
double uniformSpacing(int sourceWidth, int sourceHeight, int width, int height);

// The footprint of a CoNUS pixel as a continuous field: d(undistorted)/d(distorted) at each map
// node, from central differences of the node positions (one-sided at the edges), interpolated
// bilinearly in between. The map's own Jacobian is constant along a cell and jumps from cell to
// cell; a filter sized by it would jump with it (a visible seam at every cell edge). The GPU
// encoder gives the same values to its mesh's vertices.
class FootprintField {
public:
    explicit FootprintField(const SamplingMap& map);
    // Columns: undistorted change per unit of distorted u and of distorted v, at undistorted p
    // (clamped to [0,1]^2). Zero where the map folds (a node with det <= 0).
    glm::dmat2 inverseJacobian(glm::dvec2 p) const;

private:
    int m_columns = 0, m_rows = 0;
    std::vector<glm::dmat2> m_nodes;
};

// How each CoNUS pixel is filtered from the source; both follow the footprint rule above (the
// unit box in CoNUS pixels, the Gaussian along a long major axis).
//  - Anisotropic (the default): as GPUs' anisotropic filtering does. The footprint's principal axes
//    (the singular vectors of [a b]) set the pyramid level, where the minor axis is
//    kEncodeAnisotropicMinorTexels texels, and a row of taps along the major axis (at most a texel
//    apart, at most kEncodeAnisotropicMaxTaps: a longer one moves up a level) weighted by the box
//    convolved with the Gaussian. The pyramid's box levels do the minor axis's filtering. The box's
//    projection on the major axis is taken as a unit box (the same variance for every direction).
//  - Ewa: the tap grid over the footprint's parallelogram in (s,t) described above, with the exact
//    weight of each tap; the GL encoder's twin, and the reference the anisotropic kernel is tested
//    against.
// Under a uniform map (every node where the identity puts it) the encoder takes the EWA filter
// whatever is asked: there it is the exact area average at integer ratios, and the uniform image
// (`conus uniform`, the baseline every gain is measured against) stays that average.
enum class EncodeFilter { Anisotropic, Ewa };
// Whether every node of the map sits where the identity puts it (to float rounding): where the
// encoders take the EWA filter whatever is asked.
bool isUniformMap(const SamplingMap& map);
constexpr auto enumNameTable(EncodeFilter) {
    return makeEnumNameTable<EncodeFilter>("encode filter",
                                           {{EncodeFilter::Anisotropic, "anisotropic"}, {EncodeFilter::Ewa, "ewa"}}, true);
}
inline constexpr double kEncodeAnisotropicMinorTexels = 2.0;
inline constexpr int kEncodeAnisotropicMaxTaps = 32;

// The box-filtered levels of one source that the CPU encoder builds as footprints need them (level
// k the exact area halving of level k-1, down to 1x1), kept between encodes: an encode given one in
// EncodeOptions::keptLevels takes the levels it holds and leaves there those it built, so encodes
// of one picture after another (a server answering frames of it) build each level once. It belongs
// to one source: an encode of another (pixels elsewhere, another size or channels) empties it
// first; a caller that changes a source's pixels in place clears it. One encode at a time may use it.
class EncodeLevels {
public:
    // Bytes of pixels held.
    std::int64_t bytes() const;
    void clear();

private:
    friend class EncodeLevelsAccess;
    const float* m_source = nullptr;
    int m_width = 0, m_height = 0, m_channels = 0;
    std::vector<Image> m_levels;  // [k] is level k (level 0, the source, is never held); empty where not built
};

struct EncodeOptions {
    int width = 0, height = 0;  // CoNUS image size
    int threads = 0;
    ProgressFn progress;
    EncodeFilter filter = EncodeFilter::Anisotropic;
    EncodeLevels* keptLevels = nullptr;  // the CPU encoder's; GPU encoders build their own
    // Where given, the CPU encoder fills it with each CoNUS pixel's low-pass share (row-major, one
    // value a pixel: how far it low-passed that pixel's long axis, fit.h), which the fit of this
    // encode then need not find again (FitOptions::lowPassShare); GPU encoders empty it.
    std::vector<float>* lowPassShare = nullptr;
};

// Throws conus::Error(LimitExceeded) when encoding `source` (its size and channels) to a width x
// height CoNUS image would hold more than `maxBytes` of pixels as float, the source's and the
// CoNUS image's together (limits.h: kMaxEncodeBytes). Every encoder calls it before allocating.
void checkEncodeMemory(const Image& source, int width, int height, std::int64_t maxBytes = kMaxEncodeBytes);

Image encodeImage(const Image& source, const SamplingMap& map, const EncodeOptions& options);

// Every level of `source`'s pyramid built into `kept` now, as encodes with keptLevels = &kept build
// them on first use: a later encode of `source` (unmoved in memory) starts at its taps.
void buildEncodeLevels(const Image& source, EncodeLevels& kept, int threads = 0);

// A picture read from 8-bit codes, kept as them: interleaved like Image's pixels. The colour
// channels (R, G, B, Y) are sRGB-encoded, the others (alpha) code / 255, straight (not
// premultiplied). It stands for the float picture linearImage() makes, a quarter of its memory.
struct EightBitImage {
    int width = 0, height = 0;
    std::vector<std::string> channels;
    std::vector<std::uint8_t> codes;
    int channelCount() const { return static_cast<int>(channels.size()); }
};
// The linear value of each code of a colour channel (sRGB curve, computed in double and rounded
// once, as imageio decodes 8-bit sRGB), and of any other channel's (code / 255).
const float* srgbCodeToLinear();
const float* codeToUnit();
bool isColourChannelName(const std::string& name);  // R, G, B, Y: the channels a display encodes
// The float picture `codes` stands for (throws conus::Error InvalidArgument on an inconsistent one).
Image linearImage(const EightBitImage& codes);
// The same CoNUS image as encodeImage(linearImage(source), ...) to float rounding, without that
// float picture: the pyramid's first level is built from the codes through the tables above, and
// the source's own pixels are made linear only in the row bands that footprints on it read.
Image encodeImage(const EightBitImage& source, const SamplingMap& map, const EncodeOptions& options);

// The plain baseline: box-filter area downsample to width x height (exact area weights). It only
// shrinks: a width or height above the source's throws conus::Error(InvalidArgument).
Image areaDownsample(const Image& source, int width, int height, int threads = 0);

}  // namespace conus::codec
