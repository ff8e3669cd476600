// Writes CoNUS-like files with OpenEXR directly, headers edited at will: for rules and limits no
// valid ConusFile can break (format tests only; they link OpenEXR).
#pragma once

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <ImfVecAttribute.h>

#include <functional>
#include <string>
#include <vector>

#include "conus/format/container.h"

namespace conus::format::testing {

using Mutate = std::function<void(Imf::Header& conus, Imf::Header& map)>;

// Imf::Header::erase of OpenEXR 3.1 leaks the attribute (LeakSanitizer reports it): rebuild the
// header without it instead.
inline void eraseAttribute(Imf::Header& h, const std::string& name) {
    Imf::Header rebuilt;
    for (auto it = h.begin(); it != h.end(); ++it)
        if (name != it.name()) rebuilt.insert(it.name(), it.attribute());
    h = rebuilt;
}

// Writes what writeConusFile would, without validation, after `mutate` edits the headers; every
// channel of each header gets pixel data, so any channel layout can be written.
inline void writeRaw(const std::string& path, const ConusFile& f, const Mutate& mutate, bool withMap = true) {
    Imf::Header conus(f.image.width, f.image.height);
    conus.setName("conus");
    conus.setType(Imf::SCANLINEIMAGE);
    for (const std::string& c : f.image.channels) conus.channels().insert(c, Imf::Channel(Imf::FLOAT));
    conus.insert("conus:version", Imf::IntAttribute(1));
    conus.insert("conus:sourceSize", Imf::V2iAttribute(Imath::V2i(f.sourceWidth, f.sourceHeight)));
    conus.insert("conus:dataKind", Imf::StringAttribute("image"));
    conus.insert("conus:depthKind", Imf::StringAttribute("none"));
    Imf::Header map(conus.displayWindow(), Imath::Box2i({0, 0}, {f.map.columns - 1, f.map.rows - 1}));
    map.setName("samplingmap");
    map.setType(Imf::SCANLINEIMAGE);
    map.channels().insert("ud", Imf::Channel(Imf::FLOAT));
    map.channels().insert("vd", Imf::Channel(Imf::FLOAT));
    mutate(conus, map);

    std::vector<Imf::Header> headers{conus};
    if (withMap) headers.push_back(map);
    Imf::MultiPartOutputFile out(path.c_str(), headers.data(), int(headers.size()));
    std::vector<std::vector<float>> store;
    for (int p = 0; p < int(headers.size()); ++p) {
        const Imf::Header& h = headers[p];
        const Imath::Box2i dw = h.dataWindow();
        const int w = dw.max.x - dw.min.x + 1, rows = dw.max.y - dw.min.y + 1;
        Imf::FrameBuffer fb;
        for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
            // OpenEXR writes only from slices of the channel's own type; 0.5f has the bits of a
            // plausible UINT too, and HALF channels get a half's worth of each float.
            std::vector<float>& buf = store.emplace_back(std::size_t(w) * rows, 0.5f);
            const Imf::PixelType type = it.channel().type;
            if (p == 1 && (std::string(it.name()) == "ud" || std::string(it.name()) == "vd")) {
                const int off = std::string(it.name()) == "ud" ? 0 : 1;
                for (std::size_t k = 0; k < buf.size() && 2 * k + 1 < f.map.xy.size(); ++k) buf[k] = f.map.xy[2 * k + off];
            }
            char* base = reinterpret_cast<char*>(buf.data()) - (std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * w) * 4;
            const std::size_t size = type == Imf::HALF ? 2 : 4;
            if (type == Imf::HALF) base = reinterpret_cast<char*>(buf.data());  // zero-origin windows only
            fb.insert(it.name(), Imf::Slice(type, base, size, size * w, it.channel().xSampling, it.channel().ySampling));
        }
        Imf::OutputPart part(out, p);
        part.setFrameBuffer(fb);
        part.writePixels(rows);
    }
}

}  // namespace conus::format::testing
