// Fuzz harness: the elevation-model readers of `conus heightfield` and `bake relief`
// (sceneio/dem_file.h) on arbitrary bytes: a NumPy .npz (zip) archive when the input starts like
// one, else an .npy array. A model that reads must hold finite heights within the sample cap; anything else must be
// a one-line conus::Error.
#include <cmath>
#include <string>

#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/sceneio/dem_file.h"
#include "fuzz.h"
#include "scene_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const SceneFixture fixture("dem");
    return readOrRefuse([&] {
        const std::string path = fixture.write(startsWith(data, size, "PK") ? "npz" : "npy", data, size);
        const conus::sceneio::Dem dem = conus::sceneio::readDem(path, 1.0);
        CONUS_FUZZ_CHECK(std::int64_t(dem.heights.width) * dem.heights.height <= conus::kMaxDemSamples, "sample cap");
        for (float h : dem.heights.pixels) CONUS_FUZZ_CHECK(std::isfinite(h), "heights are finite");
    });
}
