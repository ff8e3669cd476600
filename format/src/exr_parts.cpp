// The pixels of one part of a multipart EXR, read and written by its index (exr_parts_pvt.h).
#include "exr_parts_pvt.h"

#include <ImfFrameBuffer.h>
#include <ImfInputPart.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfThreading.h>
#include <ImfTiledInputPart.h>
#include <half.h>

#include <mutex>
#include <vector>

#include "conus/core/parallel.h"

namespace conus::format::detail {
namespace {

// The map's nodes, interleaved (u, v) in GridNodes, as the part's two planes `ud` and `vd`.
Imf::FrameBuffer mapFrameBuffer(const GridNodes& grid) {
    Imf::FrameBuffer fb;
    char* base = const_cast<char*>(reinterpret_cast<const char*>(grid.xy.data()));
    const std::size_t xStride = 2 * sizeof(float);
    fb.insert(kMapChannelU, Imf::Slice(Imf::FLOAT, base, xStride, xStride * grid.columns));
    fb.insert(kMapChannelV, Imf::Slice(Imf::FLOAT, base + sizeof(float), xStride, xStride * grid.columns));
    return fb;
}

}  // namespace

// OpenEXR (de)compresses the line blocks of one writePixels/readPixels call on its global thread
// pool, which is empty unless someone sizes it: one thread a core, once, unless the program set
// its own. A 1024^2 zip write was a serial tail of `conus encode` (bench/notes/2026-11-24-end-to-end.md).
void useExrThreads() {
    static std::once_flag once;
    std::call_once(once, [] {
        if (Imf::globalThreadCount() == 0) Imf::setGlobalThreadCount(threadCount(0));
    });
}

void readImagePart(Imf::MultiPartInputFile& file, int index, const PartModel& part, Image& image) {
    std::vector<std::string> names;
    for (const ChannelModel& c : part.channels) names.push_back(c.name);
    image = makeImage(int(part.dataWindow.width()), int(part.dataWindow.height()), std::move(names));
    const std::size_t nc = image.channels.size();
    const std::size_t xStride = nc * sizeof(float);
    const std::size_t yStride = xStride * image.width;
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < nc; ++c) {
        // Fill 0 for nothing: every channel exists, so OpenEXR writes every value.
        fb.insert(image.channels[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(image.pixels.data() + c), xStride, yStride));
    }
    if (part.type == Imf::TILEDIMAGE) {
        Imf::TiledInputPart in(file, index);
        in.setFrameBuffer(fb);
        in.readTiles(0, in.numXTiles(0) - 1, 0, in.numYTiles(0) - 1, 0, 0);
    } else {
        Imf::InputPart in(file, index);
        in.setFrameBuffer(fb);
        in.readPixels(0, image.height - 1);
    }
}

void writeImagePart(Imf::MultiPartOutputFile& exr, int index, const Image& im, PixelType pixelType) {
    // OpenEXR converts types when reading but not when writing: HALF channels get their own
    // planar half buffers (rounded to nearest), FLOAT ones are written from the image.
    const std::size_t nc = im.channels.size();
    const std::size_t count = std::size_t(im.width) * im.height;
    std::vector<std::vector<Imath::half>> halves;
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < nc; ++c) {
        if (!isDepthChannel(im.channels[c]) && pixelType == PixelType::Half) {
            std::vector<Imath::half>& h = halves.emplace_back(count);
            for (std::size_t i = 0; i < count; ++i) h[i] = Imath::half(im.pixels[i * nc + c]);
            fb.insert(im.channels[c], Imf::Slice(Imf::HALF, reinterpret_cast<char*>(h.data()), sizeof(Imath::half),
                                                 sizeof(Imath::half) * im.width));
        } else {
            fb.insert(im.channels[c], Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(im.pixels.data() + c)),
                                                 nc * sizeof(float), nc * sizeof(float) * im.width));
        }
    }
    Imf::OutputPart out(exr, index);
    out.setFrameBuffer(fb);
    out.writePixels(im.height);
}

void readMapPart(Imf::MultiPartInputFile& file, int index, const PartModel& part, GridNodes& grid) {
    grid.columns = int(part.dataWindow.width());
    grid.rows = int(part.dataWindow.height());
    grid.xy.assign(std::size_t{2} * grid.columns * grid.rows, 0.0f);
    Imf::InputPart in(file, index);
    in.setFrameBuffer(mapFrameBuffer(grid));
    in.readPixels(0, grid.rows - 1);
}

void writeMapPart(Imf::MultiPartOutputFile& exr, int index, const GridNodes& grid) {
    Imf::OutputPart out(exr, index);
    out.setFrameBuffer(mapFrameBuffer(grid));
    out.writePixels(grid.rows);
}

}  // namespace conus::format::detail
