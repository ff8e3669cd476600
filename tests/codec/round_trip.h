// A CoNUS image decoded beside the uniform image of the same pixel count: what the codec tests
// measure a map's gain or loss on.
#pragma once

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"

namespace conus::test {

struct DecodedPair {
    Image view;     // the CoNUS image decoded at the source's size (the whole frame)
    Image uniform;  // the source area-downsampled to the CoNUS image's size, resized back bilinearly
};

// `conus`, a CoNUS image of `source` through `map`, and its uniform twin, both at the source's size.
inline DecodedPair decodedBeside(const Image& source, const codec::SamplingMap& map, const Image& conus) {
    codec::DecodeOptions d;
    d.width = source.width;
    d.height = source.height;
    return {codec::decodeImage(conus, map, d), codec::resizeBilinear(codec::areaDownsample(source, conus.width, conus.height), {}, source.width, source.height)};
}

// The same of `source` encoded through `map` at width x height (the default filter, no fit).
inline DecodedPair roundTrip(const Image& source, const codec::SamplingMap& map, int width, int height) {
    codec::EncodeOptions e;
    e.width = width;
    e.height = height;
    return decodedBeside(source, map, codec::encodeImage(source, map, e));
}

}  // namespace conus::test
