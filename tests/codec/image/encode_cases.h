// The maps and options the CPU encoder's tests share: two foci (any aspect, density or add
// composition), an encode to w x h, and both filters.
#pragma once

#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/encode.h"

namespace conus::test {

inline codec::SamplingMap twoFoci(double aspect = 1.0, codec::FociComposition composition = codec::FociComposition::Density) {
    const std::vector<codec::Focus> foci = {{0.3, 0.35, 0.08, 4}, {0.7, 0.6, 0.06, 3}};
    codec::FociOptions options;
    options.aspect = aspect;
    options.composition = composition;
    return codec::buildFociMap(foci, options);
}

inline codec::EncodeOptions sized(int w, int h, int threads = 0, codec::EncodeFilter filter = codec::EncodeFilter::Anisotropic) {
    codec::EncodeOptions o;
    o.width = w;
    o.height = h;
    o.threads = threads;
    o.filter = filter;
    return o;
}

inline constexpr codec::EncodeFilter kFilters[] = {codec::EncodeFilter::Anisotropic, codec::EncodeFilter::Ewa};

}  // namespace conus::test
