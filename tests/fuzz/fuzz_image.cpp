// Fuzz harness: ordinary image files through conus::imageio (the one reader of PNG, JPEG, TIFF,
// EXR, BMP, HDR, PPM, TGA, DDS, PSD): its JPEG scan count, its refusal of what is not one flat
// picture (TIFF pages, DDS volumes, cube maps and arrays), its size checks, channel placement,
// colour conversion, orientation and metadata on top of OpenImageIO. The first byte picks the
// format (the reader goes by the name's extension), the rest is the file, written to /dev/shm
// (memory); with its top bit set the file is read as standard input instead (the format by its
// first bytes, the stream bounded by what its header declares). A file that reads must keep the reader's promises: within the limits, one line per
// error, values placed by name.
// Each run is kept cheap, since a million are asked for: when fuzzing, only the named format's
// reader is tried (OpenImageIO's try_all_readers off; by default a file its extension's reader refuses goes to
// every reader OpenImageIO has, LibRaw's among them, whose start alone clears megabytes: three
// quarters of a run's time went there), and pictures past 4096 pixels are refused before any
// decoding, as any caller may lower the limit (the refusal past it is what the hostile tests run).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>

#ifdef CONUS_FUZZING
#include <OpenImageIO/imageio.h>
#endif

#include "conus/core/error.h"
#include "conus/imageio/image_file.h"
#include "fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const char* kExtensions[] = {"png", "jpg", "tif", "exr", "bmp", "hdr", "ppm", "tga", "dds", "psd"};
    if (size < 1) return 0;
#ifdef CONUS_FUZZING  // the replay (ctest) keeps OpenImageIO's default, as the tools have it
    static const bool namedReaderOnly = OIIO::attribute("try_all_readers", 0);
    (void)namedReaderOnly;
#endif
    const std::string path = "/dev/shm/conus-fuzz-image-" + std::to_string(::getpid()) + "." +
                             kExtensions[data[0] % (sizeof kExtensions / sizeof *kExtensions)];
    {
        std::FILE* f = std::fopen(path.c_str(), "wb");
        CONUS_FUZZ_CHECK(f != nullptr, "cannot write to /dev/shm");
        CONUS_FUZZ_CHECK(std::fwrite(data + 1, 1, size - 1, f) == size - 1, "fwrite");
        std::fclose(f);
    }
    const bool throughStdin = data[0] & 0x80;
    for (const bool raw : {false, true}) {
        if (throughStdin) CONUS_FUZZ_CHECK(std::freopen(path.c_str(), "rb", stdin) != nullptr, "freopen");
        conus::imageio::ReadOptions options;
        if (raw) options.colorspace = conus::Transfer::Raw;
        // A lowered cap, as any caller may set: a 16 KB input may declare up to 64 MB of samples
        // (4096:1), and committing that much under ASan, twice per input, held the harness to
        // ~10 executions a second.
        options.limits.maxPixels = std::int64_t{1} << 12;
        readOrRefuse([&] {
            const conus::imageio::ImageFile file = conus::imageio::readImageFile(throughStdin ? "-" : path, options);
            const conus::Image& image = file.image;
            CONUS_FUZZ_CHECK(image.width >= 1 && image.height >= 1 && image.width <= conus::kMaxImageSide &&
                                 image.height <= conus::kMaxImageSide &&
                                 std::int64_t{image.width} * image.height <= options.limits.maxPixels,
                             "a read image is within the limits");
            CONUS_FUZZ_CHECK(image.pixels.size() ==
                                 static_cast<std::size_t>(image.width) * image.height * image.channels.size(),
                             "pixels match the size");
            CONUS_FUZZ_CHECK(file.info.nonFinite == conus::imageio::countNonFinite(image), "non-finite count");
        });
    }
    ::unlink(path.c_str());
    return 0;
}
