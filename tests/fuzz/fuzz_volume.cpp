// Fuzz harness: the volume readers on arbitrary bytes: NRRD through teem (attached data, or a
// detached header naming files beside it and the traps of scene_fixture.h), VolPack's .den, and
// raw bricks, whose layout ("WxHxD:type[:spacing]") is the input's first line. A volume that reads
// must satisfy checkVolume and the caps given; anything else must be a one-line conus::Error.
#include <string>

#include "conus/core/error.h"
#include "conus/sceneio/volume_file.h"
#include "fuzz.h"
#include "scene_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const SceneFixture fixture("volume");
    conus::sceneio::VolumeReadOptions options;
    options.maxVoxels = 1 << 18;  // a 16 KB input holds no more unless compressed
    return readOrRefuse([&] {
        conus::Volume volume;
        if (startsWith(data, size, "NRRD")) {
            // Attached data or a detached header alike: teem tells them apart by the header.
            volume = conus::sceneio::readVolume(fixture.write(size % 2 ? "nrrd" : "nhdr", data, size), options);
        } else if (size >= 2 && ((data[0] == 1 && data[1] == 0) || (data[0] == 0 && data[1] == 1))) {
            volume = conus::sceneio::readVolume(fixture.write("den", data, size), options);
        } else {
            const std::string text(reinterpret_cast<const char*>(data), size);
            const std::size_t newline = std::min(text.find('\n'), std::size_t(200));
            const std::string layout = text.substr(0, newline);
            const std::size_t body = std::min(size, newline + 1);
            const std::string path = fixture.write("raw", data + body, size - body);
            volume = conus::sceneio::readVolume("raw:" + layout + ":" + path, options);
        }
        conus::checkVolume(volume, "fuzzed volume");
        CONUS_FUZZ_CHECK(volume.values.size() <= std::size_t(options.maxVoxels), "voxel cap");
    });
}
