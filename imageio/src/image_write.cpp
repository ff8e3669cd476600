// Writing image files through OpenImageIO (oiio_module_pvt.h's writeImageFile): what each format
// holds, channels by name, colour from linear light to what the format stores, metadata, and the
// atomic write through an IOProxy. Failures become conus::Error naming the user's path.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>

#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "image_colour_pvt.h"
#include "oiio_module_pvt.h"

namespace conus::imageio::oiio {
namespace {

// ---- what a file format holds ------------------------------------------------------------------

struct FormatTraits {
    std::vector<SampleType> sampleTypes;  // the first is the natural one
    bool anyChannels = false;             // TIFF, EXR, DPX: any number of named channels
    bool alpha = false;
};

FormatTraits traitsOf(const std::string& formatName, const OIIO::ImageOutput& output) {
    FormatTraits t;
    t.anyChannels = output.supports("nchannels") != 0;
    t.alpha = output.supports("alpha") != 0;
    using enum SampleType;
    if (formatName == "png" || formatName == "pnm" || formatName == "jpeg2000" || formatName == "dpx")
        t.sampleTypes = {Uint8, Uint16};
    else if (formatName == "tiff")
        t.sampleTypes = {Uint16, Uint8, Float, Half};
    else if (formatName == "openexr")
        t.sampleTypes = {Half, Float};
    else if (formatName == "hdr")
        t.sampleTypes = {Float};
    else
        t.sampleTypes = {Uint8};
    return t;
}

bool isInteger(SampleType t) { return t == SampleType::Uint8 || t == SampleType::Uint16 || t == SampleType::Uint32; }

OIIO::TypeDesc typeDescOf(SampleType t) {
    switch (t) {
        case SampleType::Uint8: return OIIO::TypeDesc::UINT8;
        case SampleType::Uint16: return OIIO::TypeDesc::UINT16;
        case SampleType::Uint32: return OIIO::TypeDesc::UINT32;
        case SampleType::Half: return OIIO::TypeDesc::HALF;
        case SampleType::Float: return OIIO::TypeDesc::FLOAT;
    }
    return OIIO::TypeDesc::FLOAT;
}

std::string joinTypes(const std::vector<SampleType>& types) {
    std::string s;
    for (std::size_t i = 0; i < types.size(); ++i)
        s += std::string(i == 0 ? "" : i + 1 == types.size() ? " or " : ", ") + enumName(types[i]);
    return s;
}

void applyMetadata(const SourceEncoding& source, bool withIcc, OIIO::ImageSpec& spec) {
    for (const MetadataItem& item : source.metadata) {
        if (const auto* s = std::get_if<std::string>(&item.value)) spec.attribute(item.name, *s);
        else if (const auto* i = std::get_if<int>(&item.value)) spec.attribute(item.name, *i);
        else if (const auto* f = std::get_if<float>(&item.value)) spec.attribute(item.name, *f);
        else if (const auto* d = std::get_if<double>(&item.value)) spec.attribute(item.name, OIIO::TypeDesc::DOUBLE, d);
    }
    if (withIcc && !source.iccProfile.empty())
        spec.attribute("ICCProfile", OIIO::TypeDesc(OIIO::TypeDesc::UINT8, static_cast<int>(source.iccProfile.size())),
                       source.iccProfile.data());
}

// OpenImageIO's writers write through this proxy into an AtomicFile: every byte checked, and the
// file renamed into place only after the writer closed without error.
class AtomicProxy final : public OIIO::Filesystem::IOProxy {
public:
    explicit AtomicProxy(AtomicFile& file) : IOProxy(file.destination(), IOProxy::Write), m_file(file) {}
    const char* proxytype() const override { return "conus-atomic"; }
    size_t write(const void* buf, size_t size) override {
        const std::size_t n = pwrite(buf, size, m_pos);
        m_pos += static_cast<int64_t>(n);
        return n;
    }
    size_t pwrite(const void* buf, size_t size, int64_t offset) override {
        if (!m_error.empty()) return 0;
        try {
            if (static_cast<std::uint64_t>(offset) == m_file.size()) m_file.write(buf, size);
            else m_file.writeAt(static_cast<std::uint64_t>(offset), buf, size);
        } catch (const Error& e) {
            m_error = e.what();
            return 0;
        }
        return size;
    }
    size_t read(void* buf, size_t size) override {
        const std::size_t n = pread(buf, size, m_pos);
        m_pos += static_cast<int64_t>(n);
        return n;
    }
    size_t pread(void* buf, size_t size, int64_t offset) override {
        if (!m_error.empty()) return 0;
        try {
            return m_file.readAt(static_cast<std::uint64_t>(offset), buf, size);
        } catch (const Error& e) {
            m_error = e.what();
            return 0;
        }
    }
    bool seek(int64_t offset) override {
        m_pos = offset;
        return true;
    }
    size_t size() const override { return static_cast<size_t>(m_file.size()); }
    const std::string& failure() const { return m_error; }

private:
    AtomicFile& m_file;
};

struct Target {
    std::unique_ptr<OIIO::ImageOutput> output;
    std::string formatName;
    FormatTraits traits;
    SampleType sampleType = SampleType::Uint8;
};

Target targetFor(const std::string& path, const WriteOptions& options) {
    Target t;
    t.output = OIIO::ImageOutput::create(path);
    if (!t.output) {
        const std::string ext = std::filesystem::path(path).extension().string();
        (void)OIIO::geterror();
        throw Error(ErrorCode::InvalidArgument,
                    path + ": no image writer for " + (ext.empty() ? std::string("a name without an extension") : "'" + ext + "'") +
                        " (use .png, .jpg, .tif, .exr, .bmp, .hdr, ...)");
    }
    t.formatName = t.output->format_name();
    t.traits = traitsOf(t.formatName, *t.output);
    const auto holds = [&](SampleType s) {
        return std::find(t.traits.sampleTypes.begin(), t.traits.sampleTypes.end(), s) != t.traits.sampleTypes.end();
    };
    if (options.sampleType) {
        if (!holds(*options.sampleType))
            throw Error(ErrorCode::InvalidArgument, path + ": " + t.formatName + " holds " + joinTypes(t.traits.sampleTypes) +
                                                        " samples, not " + enumName(*options.sampleType));
        t.sampleType = *options.sampleType;
        return t;
    }
    t.sampleType = t.traits.sampleTypes.front();
    const std::optional<SampleType> source = options.source ? options.source->sampleType : std::nullopt;
    if (source && holds(*source)) t.sampleType = *source;
    else if (source && !isInteger(*source) && holds(SampleType::Float)) t.sampleType = SampleType::Float;  // linear stays float
    return t;
}

}  // namespace

void checkImageOutput(const std::string& path, const WriteOptions& options) {
    checkOutputPath(path);
    (void)targetFor(path, options);
}

std::string sampleTypesOf(const std::string& path) {
    auto output = OIIO::ImageOutput::create(path);
    if (!output) return "no";
    return joinTypes(traitsOf(output->format_name(), *output).sampleTypes);
}

void writeImageFile(const std::string& path, const Image& image, const WriteOptions& options) {
    checkImage(image, "writeImageFile");
    Target target = targetFor(path, options);
    const bool integer = isInteger(target.sampleType);

    // Channels by name: colour first in display order, then alpha, then (formats with named
    // channels only) the rest in the image's order.
    ChannelRoles roles = rolesOf(image);
    if (roles.colour.empty()) {  // no R,G,B or Y: show the first non-alpha channel as grey
        for (int c = 0; c < image.channelCount() && roles.colour.empty(); ++c)
            if (c != roles.alpha) roles.colour = {c};
        if (roles.colour.empty()) roles.colour = {0};
    }
    std::vector<int> order = roles.colour;
    int alpha = -1;
    if (roles.alpha >= 0 && target.traits.alpha && std::find(order.begin(), order.end(), roles.alpha) == order.end()) {
        alpha = static_cast<int>(order.size());
        order.push_back(roles.alpha);
    }
    if (target.traits.anyChannels)
        for (int c = 0; c < image.channelCount(); ++c)
            if (std::find(order.begin(), order.end(), c) == order.end()) order.push_back(c);
    const int channels = static_cast<int>(order.size());
    std::vector<int> colour(roles.colour.size());
    for (std::size_t i = 0; i < colour.size(); ++i) colour[i] = static_cast<int>(i);

    constexpr int kJpegMaxSide = 65500;  // libjpeg ends the process on larger images
    if (target.formatName == "jpeg" && (image.width > kJpegMaxSide || image.height > kJpegMaxSide))
        throw Error(ErrorCode::InvalidArgument, path + ": JPEG holds at most 65500 pixels a side, not " +
                                                    std::to_string(image.width) + "x" + std::to_string(image.height));

    const auto count = static_cast<std::size_t>(image.width) * image.height;
    std::vector<float> pixels(count * channels);
    for (std::size_t p = 0; p < count; ++p)
        for (int i = 0; i < channels; ++i) pixels[p * channels + i] = image.pixels[p * image.channelCount() + order[i]];

    // What the written values encode.
    const SourceEncoding* source = options.source;
    const bool raw = options.meaning == PixelMeaning::Raw || (source && source->transfer == Transfer::Raw);
    Transfer written = Transfer::Linear;
    if (raw) written = Transfer::Raw;
    else if (integer)
        written = source && source->transfer == Transfer::Linear && source->sampleType && isInteger(*source->sampleType)
                      ? Transfer::Linear
                      : Transfer::Srgb;

    if (!raw) {
        const float gain = static_cast<float>(std::exp2(options.display.exposure));
        const ToneMap toneMap = integer ? options.display.toneMap : ToneMap::None;
        if (options.meaning == PixelMeaning::Linear) {
            // Display formats store straight alpha; the colour is encoded from straight linear values.
            if (integer && alpha >= 0) premultiply(pixels.data(), image.width, image.height, channels, alpha, false);
            if (gain != 1.0f || toneMap != ToneMap::None)
                for (std::size_t p = 0; p < count; ++p)
                    for (int c : colour) pixels[p * channels + c] = exposeAndToneMap(pixels[p * channels + c], gain, toneMap);
            if (written == Transfer::Srgb)
                convertColour(pixels.data(), image.width, image.height, channels, colour, "linear", "sRGB", path);
        } else if (written != Transfer::Srgb) {  // display artwork into a linear format
            convertColour(pixels.data(), image.width, image.height, channels, colour, "sRGB", "linear", path);
        }
    }

    OIIO::ImageSpec spec(image.width, image.height, channels, typeDescOf(target.sampleType));
    spec.channelnames.clear();
    for (int c : order) spec.channelnames.push_back(image.channels[c]);
    spec.alpha_channel = alpha;
    spec.z_channel = -1;
    for (int i = 0; i < channels; ++i)
        if (spec.channelnames[i] == "Z") spec.z_channel = i;
    if (written == Transfer::Srgb) spec.attribute("oiio:ColorSpace", "sRGB");
    else if (written == Transfer::Linear) spec.attribute("oiio:ColorSpace", "Linear");
    if (integer && alpha >= 0) spec.attribute("oiio:UnassociatedAlpha", 1);
    if (target.formatName == "openexr") spec.attribute("compression", "zip");
    // zlib level 4, not OpenImageIO's 6: a 1920x1080 photo view (bench/notes/2026-11-24-decode-pyramid.md)
    // deflated at 6 took 0.6 s of CPU, a third of `conus decode`, for a file 4% smaller than at 4,
    // which takes 0.1 s; levels 1-3 save no more time and grow the file 6-11%.
    if (target.formatName == "png") spec.attribute("png:compressionLevel", 4);
    if (source) {
        applyMetadata(*source, written != Transfer::Raw, spec);
        if (!integer && source->chromaticities && !raw)
            spec.attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8), source->chromaticities->data());
    }

    AtomicFile file(path);
    AtomicProxy proxy(file);
    // OpenImageIO 2.4.7 writes an unreadable TIFF through an IOProxy once it adds an EXIF
    // directory (measured: the header ends up pointing at the EXIF directory), so TIFF is written
    // by name into the temporary file and read back to check it.
    const bool proxied = target.formatName != "tiff" && target.output->supports("ioproxy") && target.output->set_ioproxy(&proxy);
    const std::string openPath = proxied ? path : file.temporaryPath();
    bool ok = target.output->open(openPath, spec);
    ok = ok && target.output->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
    ok = target.output->close() && ok;
    std::string reason = proxy.failure().empty() ? target.output->geterror() : proxy.failure();
    if (ok && proxy.failure().empty() && !proxied) {
        auto check = OIIO::ImageInput::open(openPath);
        if (!check || check->spec().width != spec.width || check->spec().height != spec.height) {
            ok = false;
            reason = "the finished file does not read back: " + (check ? std::string("wrong size") : OIIO::geterror());
        }
    }
    if (!ok || !proxy.failure().empty()) {
        if (reason.empty()) reason = "the " + target.formatName + " writer failed";
        for (std::size_t at; (at = reason.find(file.temporaryPath())) != std::string::npos;)
            reason.replace(at, file.temporaryPath().size(), path);  // the user's path, never the temporary one
        // A failure already worded for the destination is passed on as it is.
        throw Error(ErrorCode::Io, reason.rfind("cannot write " + path, 0) == 0 ? reason : "cannot write " + path + ": " + reason);
    }
    file.commit();
}

}  // namespace conus::imageio::oiio
