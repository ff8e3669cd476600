// The check every map builder's result must pass: the grid rules of spec/conus-format.md, as
// `conus validate` applies them (format::validateGrid), each broken rule listed on failure.
#pragma once

#include <gtest/gtest.h>

#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"

namespace conus::test {

inline void expectValid(const codec::SamplingMap& map) {
    const format::ValidationReport report = format::validateGrid(map.toGrid());
    EXPECT_TRUE(report.ok()) << report.str();
}

}  // namespace conus::test
