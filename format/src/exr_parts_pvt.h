// Private to format/: the pixels of one part of a multipart EXR, read and written by its index, and
// the stream that writes such a file through an AtomicFile (exr_parts.cpp). A container of images
// and maps (a CoNUS file's one, a reflection asset's six) is assembled from these (exr_io.cpp).
#pragma once

#include <cstdint>
#include <string>

#include <ImfIO.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>

#include "conus/core/atomic_file.h"
#include "conus/core/image.h"
#include "conus/format/container.h"
#include "header_model_pvt.h"

namespace conus::format::detail {

// Sizes OpenEXR's global thread pool before the first read or write (exr_parts.cpp says why).
void useExrThreads();

// OpenEXR writes through this stream into the AtomicFile, so every byte is checked. OpenEXR's
// destructors write the offset tables and swallow errors; a failure is therefore also remembered
// here and reported once the file object is gone.
class AtomicOStream final : public Imf::OStream {
public:
    explicit AtomicOStream(AtomicFile& file) : Imf::OStream(file.destination().c_str()), m_file(file) {}
    void write(const char c[], int n) override {
        try {
            if (m_pos == m_file.size()) m_file.write(c, static_cast<std::size_t>(n));
            else m_file.writeAt(m_pos, c, static_cast<std::size_t>(n));
        } catch (const Error& e) {
            if (m_failure.empty()) m_failure = e.what();
            throw;
        }
        m_pos += static_cast<std::uint64_t>(n);
    }
    std::uint64_t tellp() override { return m_pos; }
    void seekp(std::uint64_t pos) override { m_pos = pos; }
    const std::string& failure() const { return m_failure; }

private:
    AtomicFile& m_file;
    std::uint64_t m_pos = 0;
    std::string m_failure;
};

// Image part `index` of `file`, described by `part` (scanline or tiled; its channels in order), as
// float pixels.
void readImagePart(Imf::MultiPartInputFile& file, int index, const PartModel& part, Image& image);

// `image` into part `index` of `exr`: channels other than Z as half when `pixelType` is Half
// (rounded to nearest), all others as float; the part's header must name the same channels.
void writeImagePart(Imf::MultiPartOutputFile& exr, int index, const Image& image, PixelType pixelType);

// Sampling-map part `index` (channels ud, vd) as the grid's nodes, and back.
void readMapPart(Imf::MultiPartInputFile& file, int index, const PartModel& part, GridNodes& grid);
void writeMapPart(Imf::MultiPartOutputFile& exr, int index, const GridNodes& grid);

}  // namespace conus::format::detail
