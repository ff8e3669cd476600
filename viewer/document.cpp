#include "document.h"

#include <exception>

#include "conus/codec/image/decode.h"

namespace conus::viewer {

int Document::sourceWidth() const {
    if (!file) return 1;
    return file->sourceWidth > 0 ? file->sourceWidth : file->image.width;
}

int Document::sourceHeight() const {
    if (!file) return 1;
    return file->sourceHeight > 0 ? file->sourceHeight : file->image.height;
}

Document loadDocument(const std::string& path) {
    Document doc;
    doc.path = path;
    try {
        format::ConusFile file = format::readConusFile(path);
        doc.map.emplace(codec::SamplingMap::fromGrid(file.map));
        doc.file.emplace(std::move(file));
    } catch (const std::exception& e) {
        // Anything from the reader (OpenEXR's own exceptions are translated there) or the map.
        doc.file.reset();
        doc.map.reset();
        doc.error = aboutFile(path, *e.what() ? e.what() : "unknown error");
    }
    return doc;
}

std::string aboutFile(const std::string& path, const std::string& message) {
    return message.find(path) != std::string::npos ? message : path + ": " + message;
}

Image uniformBaseline(const std::string& path) {
    const format::ConusFile file = format::readConusFile(path);
    codec::DecodeOptions options;
    options.width = file.image.width;
    options.height = file.image.height;
    return codec::decodeImage(file.image, codec::SamplingMap::fromGrid(file.map), options);
}

}  // namespace conus::viewer
