// conus decode: reconstruct a conventional frame (any view rectangle, any size) from a CoNUS file.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "arguments.h"
#include "backend.h"
#include "commands.h"
#include "conus/codec/decode.h"
#include "conus/format/error.h"
#include "image_io.h"
#include "progress.h"

namespace conus::cli {

Command addDecodeCommand(CLI::App& root) {
    struct Options {
        std::string input, output, viewText, sizeText, cameraText, backend = "auto";
    };
    auto options = std::make_shared<Options>();
    CLI::App* command = root.add_subcommand(
        "decode", "Reconstruct a conventional frame from a CoNUS file: zoom and pan anywhere");
    command->add_option("input", options->input, "CoNUS file (.exr)")->required();
    command->add_option("-o,--output", options->output, "output image (.png, .exr, .tif, .jpg)")->required();
    command->add_option("--view", options->viewText,
                        "rectangle u0,v0,u1,v1 of the undistorted image plane (default 0,0,1,1: the whole image)");
    command->add_option("--size", options->sizeText,
                        "output size WxH (default: the view at the source's resolution)");
    command->add_option("--camera", options->cameraText,
                        "height fields: render a 3-D frame from x,y,z,lx,ly,lz,fovDeg (eye, look-at, vertical fov; "
                        "world metres) instead of a 2-D view; 'viewer' is the ground map's own viewer");
    addBackendOption(*command, options->backend);
    return {command, [options] {
                std::error_code same;
                if (std::filesystem::equivalent(options->input, options->output, same))
                    throw Error(ErrorCode::InvalidArgument, "the output " + options->output + " is the input file");
                const format::ConusFile file = format::readConusFile(options->input);
                if (!options->cameraText.empty()) {
                    // A height field seen from a camera: undistort to a mesh and render it.
                    const Size size = parseSize(options->sizeText.empty() ? "960x540" : options->sizeText);
                    const format::Image frame = renderHeightFieldFrame(
                        file, options->cameraText == "viewer" ? "" : options->cameraText, size.width, size.height,
                        options->backend);
                    writeImage(options->output, frame);
                    std::printf("wrote %s: %dx%d frame of the height field\n", options->output.c_str(), frame.width,
                                frame.height);
                    return 0;
                }
                const codec::SamplingMap map = codec::SamplingMap::fromGrid(file.map);
                codec::DecodeOptions decode;
                if (!options->viewText.empty()) decode.view = parseView(options->viewText);
                if (!options->sizeText.empty()) {
                    const Size size = parseSize(options->sizeText);
                    decode.width = size.width;
                    decode.height = size.height;
                } else {
                    const double w = std::round((decode.view.u1 - decode.view.u0) * file.sourceWidth);
                    const double h = std::round((decode.view.v1 - decode.view.v0) * file.sourceHeight);
                    if (w > format::kMaxImageSide || h > format::kMaxImageSide)
                        throw Error(ErrorCode::InvalidArgument,
                                    "the view at source resolution would be " + std::to_string(long(w)) + "x" +
                                        std::to_string(long(h)) + " pixels; give --size");
                    decode.width = std::max(1, static_cast<int>(w));
                    decode.height = std::max(1, static_cast<int>(h));
                }
                try {
                    codec::checkDecodeMemory(file.image, decode.width, decode.height);
                } catch (const Error& e) {
                    throw Error(e.code(), std::string(e.what()) + "; give a smaller --size");
                }
                Progress progress("decode " + std::to_string(decode.width) + "x" + std::to_string(decode.height));
                decode.progress = progress.callback();
                Renderer renderer(options->backend);
                const format::Image frame = renderer.decode(file.image, map, decode);
                progress.done();
                writeImage(options->output, frame);
                std::printf("wrote %s: %dx%d view [%g,%g]-[%g,%g]\n", options->output.c_str(), frame.width,
                            frame.height, decode.view.u0, decode.view.v0, decode.view.u1, decode.view.v1);
                return 0;
            }};
}

}  // namespace conus::cli
