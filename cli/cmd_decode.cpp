// conus decode: reconstruct a conventional frame (any view rectangle, any size) from a CoNUS file.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "arguments.h"
#include "backend.h"
#include "batch.h"
#include "commands.h"
#include "conus/codec/depth/depth_image.h"
#include "conus/codec/image/decode.h"
#include "conus/core/error.h"
#include "conus/renderers/gpu_image.h"
#include "image_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

struct DecodeCommandOptions {
    BatchOptions batch;
    std::string viewText, sizeText, cameraText, backend = enumName(renderers::Backend::Auto);
    PictureOptions picture;
};

// --size for a view of w x h source pixels: "512", "512x" and "x256" keep the view's aspect; "WxH"
// is taken as given, with a warning when it stretches the view.
Size sizeForView(const std::string& text, double w, double h) {
    const std::size_t x = text.find('x');
    const bool heightOnly = x == 0, widthOnly = x == std::string::npos || x + 1 == text.size();
    if (!heightOnly && !widthOnly) {
        const Size size = parseSize(text);
        const double kept = size.width * h / w;  // the height that keeps the view's aspect
        if (std::abs(kept - size.height) > std::max(1.0, 0.01 * size.height)) {
            char note[256];
            std::snprintf(note, sizeof note,
                          "--size %s stretches the view (%.0fx%.0f source pixels, aspect %.3g) to aspect %.3g; --size %dx "
                          "keeps its aspect",
                          text.c_str(), w, h, w / h, double(size.width) / size.height, size.width);
            warn(note);
        }
        return size;
    }
    const std::string side = heightOnly ? text.substr(1) : text.substr(0, x);
    const Size given = parseSize(side + "x" + side);  // the one side's checks
    const double other = heightOnly ? given.height * w / h : given.width * h / w;
    if (other > kMaxImageSide)
        throw Error(ErrorCode::InvalidArgument, "--size " + text + " would make the other side " + std::to_string(long(other)) +
                                                    " pixels, past the limit of " + std::to_string(kMaxImageSide));
    const int kept = std::max(1, static_cast<int>(std::lround(other)));
    return heightOnly ? Size{kept, given.height} : Size{given.width, kept};
}

// The view at the source's resolution unless --size says otherwise.
Size outputSize(const DecodeCommandOptions& o, const codec::View& view, const format::ConusFile& file) {
    const double w = std::round((view.u1 - view.u0) * file.sourceWidth);
    const double h = std::round((view.v1 - view.v0) * file.sourceHeight);
    if (!o.sizeText.empty()) return sizeForView(o.sizeText, (view.u1 - view.u0) * file.sourceWidth, (view.v1 - view.v0) * file.sourceHeight);
    if (w > kMaxImageSide || h > kMaxImageSide || w * h > double(kMaxImagePixels))
        throw Error(ErrorCode::InvalidArgument, "the view at source resolution would be " + std::to_string(long(w)) + "x" +
                                                    std::to_string(long(h)) + " pixels, past the limits (" +
                                                    std::to_string(kMaxImageSide) + " a side, " +
                                                    std::to_string(kMaxImagePixels) + " in all); give --size");
    return {std::max(1, static_cast<int>(w)), std::max(1, static_cast<int>(h))};
}

// A depth image's view: colour and coverage bilinear on `device`, Z nearest (depth_image.h: a
// mean across a silhouette would be a depth on neither surface); Z outside the image is the far.
Image decodeDepthImage(const renderers::Device& device, const format::ConusFile& file, const codec::SamplingMap& map,
                       const codec::DecodeOptions& decode) {
    const Image& conus = file.image;
    const int z = conus.channelIndex("Z");
    std::vector<std::string> names;
    for (const auto& name : conus.channels)
        if (name != "Z") names.push_back(name);
    Image frame;
    if (!names.empty()) {
        Image colour = makeImage(conus.width, conus.height, names);
        const std::size_t n = static_cast<std::size_t>(conus.width) * conus.height, from = conus.channels.size();
        for (std::size_t p = 0; p < n; ++p)
            for (std::size_t c = 0, k = 0; c < from; ++c)
                if (static_cast<int>(c) != z) colour.pixels[p * names.size() + k++] = conus.pixels[p * from + c];
        frame = renderers::decodeImage(device, colour, map, decode);
    }
    const Image depth = codec::decodeDepthNearest(conus, map, decode, file.depth.far);
    names.push_back("Z");
    Image out = makeImage(decode.width, decode.height, names);
    const std::size_t n = static_cast<std::size_t>(decode.width) * decode.height, c = names.size();
    for (std::size_t p = 0; p < n; ++p) {
        for (std::size_t k = 0; k + 1 < c; ++k) out.pixels[p * c + k] = frame.pixels[p * (c - 1) + k];
        out.pixels[p * c + c - 1] = depth.pixels[p];
    }
    return out;
}

// One input to one output; returns the line that says what was written.
std::string decodeOne(const DecodeCommandOptions& o, const std::string& input, const std::string& output) {
    imageio::WriteOptions write = writeOptionsOf(o.picture, nullptr);
    checkPictureOutput(output, write, {input});
    const codec::View view = o.viewText.empty() ? codec::View{} : parseView(o.viewText);
    Progress reading("read " + input);
    const format::ConusFile file = format::readConusFile(input);
    reading.done();
    write.source = &file.sourceEncoding;
    // An EXR keeps the file's own precision: a --float file decodes to float.
    if (!write.sampleType && std::filesystem::path(output).extension() == ".exr")
        write.sampleType = file.pixelType == format::PixelType::Float ? SampleType::Float : SampleType::Half;

    if (!o.cameraText.empty()) {
        // A height field seen from a camera: undistort to a mesh and render it.
        const Size size = parseSize(o.sizeText.empty() ? "960x540" : o.sizeText);
        const Image frame = heightFieldFrame(file, o.cameraText == "viewer" ? "" : o.cameraText, size.width, size.height,
                                             o.backend);
        writePicture(output, frame, writeOptionsOf(o.picture, nullptr));
        return "wrote " + output + ": " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
               " frame of the height field";
    }
    const codec::SamplingMap map = codec::SamplingMap::fromGrid(file.map);
    const Size size = outputSize(o, view, file);
    codec::DecodeOptions decode;
    decode.view = view;
    decode.width = size.width;
    decode.height = size.height;
    const bool depthImage = file.dataKind == format::DataKind::DepthImage && file.image.channelIndex("Z") >= 0;
    // A zoomed-out view takes one trilinear tap from the image's pyramid per pixel (no aliasing,
    // a fraction of the multi-tap average's work); a magnified one is the same without it.
    const bool withPyramid = !depthImage && codec::viewZoomsOut(file.image, map, view, decode.width, decode.height);
    // The picture writer holds the frame again: as float through the display transform and in the
    // output's sample type (at most 4 bytes).
    const std::int64_t writer = std::int64_t{decode.width} * decode.height * file.image.channelCount() *
                                std::int64_t(sizeof(float) + 4);
    try {
        codec::checkDecodeMemory(file.image, decode.width, decode.height, kMaxDecodeBytes, withPyramid, writer);
    } catch (const Error& e) {
        throw Error(e.code(), std::string(e.what()) + "; give a smaller --size");
    }
    Progress progress("decode " + std::to_string(decode.width) + "x" + std::to_string(decode.height));
    decode.progress = progress.callback();
    const renderers::Device device = deviceFor(o.backend, renderers::CpuPath::Faster, "decoding");
    codec::ImagePyramid pyramid;
    if (withPyramid) {
        pyramid = codec::buildPyramid(file.image);
        decode.pyramid = &pyramid;
    }
    const Image frame = depthImage ? decodeDepthImage(device, file, map, decode) : renderers::decodeImage(device, file.image, map, decode);
    progress.done();
    writePicture(output, frame, write);
    char line[256];
    std::snprintf(line, sizeof line, ": %dx%d view [%g,%g]-[%g,%g]", frame.width, frame.height, view.u0, view.v0, view.u1, view.v1);
    return "wrote " + output + line + (depthImage ? " (Z: the nearest CoNUS pixel's depth)" : "");
}

int runDecode(const DecodeCommandOptions& o) {
    // Usage first, before any input is read.
    if (!o.viewText.empty()) parseView(o.viewText);
    if (const std::string& t = o.sizeText; !t.empty()) {
        const std::size_t x = t.find('x');
        try {
            parseSize(x == 0 ? t.substr(1) + "x1" : x == std::string::npos || x + 1 == t.size() ? t.substr(0, x) + "x1" : t);
        } catch (const Error&) {  // said in the words the user wrote
            throw Error(ErrorCode::InvalidArgument, "--size '" + t + "' is not WxH, or W, Wx or xH (the view's aspect kept), " +
                                                        "each side a whole number in [1, " + std::to_string(kMaxImageSide) + "]");
        }
    }
    return runConversions(o.batch, [&o](const Job& job) { return decodeOne(o, job.input, job.output); });
}

CLI::App* declareDecode(CLI::App& root, DecodeCommandOptions& options) {
    CLI::App* command = addSubcommand(root, "decode", "Reconstruct a conventional frame from a CoNUS file: zoom and pan anywhere",
        {"conus decode photo.exr -o photo.png                          # the whole frame at source size",
         "conus decode photo.exr -o face.png --view 0.36,0.15,0.52,0.31  # zoomed on a focus",
         "conus decode hdr.exr -o hdr.png --exposure -1 --tonemap aces --size 1920x1080",
         "conus decode exr/*.exr --out-dir views/ --name '{stem}-face.jpg' --view 0.36,0.15,0.52,0.31"});
    addBatchOptions(*command, options.batch, "CoNUS file (.exr)", "output image (.png, .jpg, .tif, .exr, .bmp, ...)", "{stem}.png");
    command->add_option("--view", options.viewText,
                        "rectangle u0,v0,u1,v1 of the undistorted image plane (default 0,0,1,1: the whole image; "
                        "a part outside [0,1] shows the background)");
    command->add_option("--size", options.sizeText,
                        "output size WxH; W, Wx or xH keep the view's aspect (default: the view at the source's "
                        "resolution)");
    command->add_option("--camera", options.cameraText,
                        "height fields: render a 3-D frame from x,y,z,lx,ly,lz,fovDeg (eye, look-at, vertical fov; "
                        "world metres) instead of a 2-D view; 'viewer' is the ground map's own viewer");
    addPictureOptions(*command, options.picture);
    addBackendOption(*command, options.backend, renderers::CpuPath::Faster);
    return command;
}

}  // namespace

Command addDecodeCommand(CLI::App& root) { return defineCommand(root, declareDecode, runDecode); }

}  // namespace conus::cli
