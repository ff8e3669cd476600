// Private: resizeBilinear's view a row at a time, for a measure that keeps no view
// (FrameErrorModel::confirmed measures the uniform image's view at the source's size).
#pragma once

#include <vector>

#include "conus/core/image.h"

namespace conus::codec::detail {

// Per-axis bilinear taps of the resize, precomputed like the decoder's view columns.
struct AxisTaps {
    std::vector<int> i0, i1;
    std::vector<float> f;
};

// Rows of resizeBilinear(image, View{}, width, height); `image` must outlive it.
class ResizedRows {
public:
    ResizedRows(const Image& image, int width, int height);
    // Output row y into out (width * channels values).
    void row(int y, float* out) const;

private:
    const Image& m_image;
    int m_width;
    AxisTaps m_tx, m_ty;
};

}  // namespace conus::codec::detail
