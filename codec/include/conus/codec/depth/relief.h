// Relief assets (paper section 5, Figure 2): a height field plus colour baked into an orthographic
// CoNUS depth image (dataKind heightfield, depth kind height) that renderers::ReliefRenderer
// intersects with eye rays; and the engraved tablet, the test content made in code.
//
// World frame of an asset: the field covers x in [0, extent.x] (u, to the right) and z in
// [0, extent.y] (v, downward in the image), heights along +y above the base plane y = 0; the
// asset's camera is orthographic, looking straight down (-y) from above the highest point, so
// intersect.h's height convention (the base plane through the origin) holds.
//
// Shared rules: heights are one channel "Z" (or the only channel), colours "R","G","B" of the same
// size, linear; threads = 0 uses every core; bad sizes and values throw conus::Error
// (InvalidArgument); nothing is printed.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "conus/codec/depth/intersect.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/format/container.h"

namespace conus::codec {

// ---- The engraved tablet --------------------------------------------------------------------

struct TabletOptions {
    double width = 1.0;           // world units across (x); the depth (z) follows the ink's aspect
    double slab = 0.08;           // the field's height
    double border = 0.06;         // the raised frame's width, a fraction of the shorter side
    double frame = 0.02;          // how far the frame stands above the field
    double bevel = 0.015;         // chamfer width of the outer edge and of the frame's inner edge
    double engraving = 0.012;     // depth of the engraved strokes
};

// A tablet from `ink` (channel 0 in [0,1]: how much of each pixel the engraved strokes cover,
// e.g. text drawn through imageio::drawText): heights ("Z", world units as TabletOptions says) of
// a slab with chamfered edges, a raised frame with a chamfered inner edge, and the strokes cut
// into the field with sloped walls; and its colour (R, G, B, linear): a mottled stone, the strokes
// darker as if painted.
struct Tablet {
    Image heights, colour;
    glm::dvec2 extent;  // world size (x, z)
};
Tablet makeTablet(const Image& ink, const TabletOptions& options = {});

// ---- Baking -----------------------------------------------------------------------------------

struct ReliefBakeOptions {
    int width = 0, height = 0;     // CoNUS image size
    glm::dvec2 extent{1.0, 1.0};   // the field's world size (x, z)
    std::string units = "m";
    int threads = 0;
};

// The asset's camera: orthographic, straight down over the field, its eye `top` above the base plane.
Camera reliefCamera(glm::dvec2 extent, double top);

// The CoNUS relief asset: encodeHeightField through `map` (R, G, B, Z; Z the height), with
// reliefCamera above the highest point. `map` null: the conventional baseline of the same texel
// count (uniformHeightField, identity map).
format::ConusFile bakeRelief(const Image& heights, const Image& colour, const SamplingMap* map,
                             const ReliefBakeOptions& options);

// The default view of a relief asset (`conus render relief` without --camera): perspective, a
// three-quarter view from the front edge's side (+z) and above, 40 degrees tall, the whole box in
// the frame.
Camera defaultReliefView(const DepthImage& asset, double aspect);

// ---- Quality ---------------------------------------------------------------------------------

// PSNR (peak 1) of `frame` against `reference` over the pixels where `mask` (channel 0) is above
// 0.5 (`inside`) or not: the ROI measure of relief frames (the engraved text vs the rest). All
// three the same size; throws conus::Error(InvalidArgument) otherwise or when no pixel counts.
double maskedPsnr(const Image& frame, const Image& reference, const Image& mask, bool inside);

}  // namespace conus::codec
