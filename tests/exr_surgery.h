// Damages a multipart EXR on purpose, through OpenEXR itself: a copy with parts dropped or their
// headers edited (for the rules only a damaged file breaks). Suites that include it link OpenEXR.
#pragma once

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>

#include <functional>
#include <string>
#include <vector>

namespace conus::test {

// Copies the EXR `from` to `to` part by part: `edit` gets each part's index and header and returns
// false to leave the part out. Every channel is stored as FLOAT (the pixels as read), and a part
// whose dataWindow the edit shrank keeps the top-left of its pixels.
inline void copyExrParts(const std::string& from, const std::string& to, const std::function<bool(int, Imf::Header&)>& edit) {
    Imf::MultiPartInputFile in(from.c_str());
    std::vector<Imf::Header> headers;
    std::vector<int> kept;
    for (int p = 0; p < in.parts(); ++p) {
        Imf::Header h = in.header(p);
        for (auto it = h.channels().begin(); it != h.channels().end(); ++it) it.channel().type = Imf::FLOAT;
        if (!edit(p, h)) continue;
        headers.push_back(h);
        kept.push_back(p);
    }
    Imf::MultiPartOutputFile out(to.c_str(), headers.data(), int(headers.size()));
    for (std::size_t k = 0; k < kept.size(); ++k) {
        const Imath::Box2i dw = in.header(kept[k]).dataWindow();
        const std::size_t w = std::size_t(dw.max.x - dw.min.x + 1), h = std::size_t(dw.max.y - dw.min.y + 1);
        std::vector<std::vector<float>> planes;
        Imf::FrameBuffer fb;
        for (auto it = headers[k].channels().begin(); it != headers[k].channels().end(); ++it) {
            std::vector<float>& plane = planes.emplace_back(w * h, 0.0f);
            fb.insert(it.name(), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(plane.data()), sizeof(float), sizeof(float) * w));
        }
        Imf::InputPart reader(in, kept[k]);
        reader.setFrameBuffer(fb);
        reader.readPixels(dw.min.y, dw.max.y);
        Imf::OutputPart writer(out, int(k));
        writer.setFrameBuffer(fb);
        const Imath::Box2i written = headers[k].dataWindow();
        writer.writePixels(written.max.y - written.min.y + 1);
    }
}

}  // namespace conus::test
