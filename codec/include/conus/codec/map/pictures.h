// Pictures people would rather look at than numbers: the density of a sampling map as a heat map
// with the sampling pattern drawn over it, and side-by-side comparison strips.
#pragma once

#include <span>
#include <vector>

#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "conus/core/image.h"

namespace conus::codec {

struct DensityStats {
    double min = 0, max = 0, mean = 0;  // sampling density over the undistorted plane
};

// Density statistics from a samples x samples grid of undistorted points.
DensityStats densityStats(const SamplingMap& map, int samples = 256);

// RGB heat map of log(density) over the undistorted plane (width x height), with the lines of the
// CoNUS pixel grid (every `spacing`-th distorted column and row, mapped back through the map) drawn
// over it, focus outlines where `analytic` describes foci, and the anisotropy (map_measures.h, in
// the pixels of an image of `aspect`, per map cell): cyan contours where the footprints of CoNUS
// pixels are 2 and 4 times longer than wide, and a cyan cross where they are most elongated.
Image densityPicture(const SamplingMap& map, int width, int height, int lines, const format::AnalyticMap* analytic = nullptr,
                     double aspect = 1.0);

// Images placed left to right on a dark background, each RGB; taller ones set the strip's height.
Image sideBySide(std::span<const Image> images, int gap = 8);

// Frames of one size in rows of `columns`, 4 pixels apart on black, each RGB: an animation's
// contact sheet.
Image contactSheet(std::span<const Image> tiles, int columns);

// The image as RGB (grey for one channel; other channels dropped) for pictures and PSNR.
Image toRgb(const Image& image);

}  // namespace conus::codec
