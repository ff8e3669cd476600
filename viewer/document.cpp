#include "document.h"

#include <exception>

#include "conus/codec/builders/foci_budget.h"
#include "conus/codec/builders/importance.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "conus/imageio/image_file.h"

namespace conus::viewer {

int Document::sourceWidth() const {
    if (!file) return 1;
    return file->sourceWidth > 0 ? file->sourceWidth : file->image.width;
}

int Document::sourceHeight() const {
    if (!file) return 1;
    return file->sourceHeight > 0 ? file->sourceHeight : file->image.height;
}

Document loadDocument(const std::string& path, std::span<const codec::Focus> foci) {
    Document doc;
    doc.path = path;
    try {
        format::ConusFile file = foci.empty() ? format::readConusFile(path) : encodedPicture(path, foci);
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

format::ConusFile encodedPicture(const std::string& path, std::span<const codec::Focus> foci) {
    const imageio::ImageFile picture = imageio::readImageFile(path);
    const Image& source = picture.image;
    const auto [width, height] = codec::defaultConusSize(source.width, source.height);
    codec::checkEncodeMemory(source, width, height);
    codec::FociMapRequest request;
    // The budget's model takes the encode's errors as `encode` does: colour as a display shows it,
    // raw data as stored.
    request.model.space = picture.info.encoding.transfer == Transfer::Raw ? codec::ErrorSpace::Linear : codec::ErrorSpace::Display;
    const Image detail = codec::ruleImportance(codec::ImportanceRule::Detail, imageio::displayEncoded(source));
    request.detail = &detail;
    codec::FociMap built = codec::budgetedFociMap(source, foci, width, height, request);
    const codec::SamplingMap& map = built.budget.map;
    Image encoded;
    if (built.budget.encode) {
        encoded = built.budget.encode->image;  // the confirming encode of this map, fitted as `encode` fits
    } else {
        std::vector<float> share;
        encoded = codec::encodeImage(source, map, {width, height, 0, {}, request.model.filter, nullptr, &share});
        codec::FitOptions fit;
        fit.lowPassShare = &share;
        fit.iterations = request.model.fitIterations;
        fit.holdLowPass = request.model.fitHold;
        fit.method = request.model.fitMethod;
        codec::fitToDecoder(source, map, encoded, fit);
    }
    return codec::makeImageFile(std::move(encoded), map, source.width, source.height, picture.info.encoding, std::move(built.analytic));
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
