#include "encoding.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "conus/core/atomic_file.h"

#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "conus/renderers/gpu_image.h"
#include "progress.h"

namespace conus::cli {

void addStorageOptions(CLI::App& command, StorageOptions& options, renderers::CpuPath cpuPath) {
    command.add_option("--size", options.sizeText, "CoNUS image size WxH (default: a quarter of each source side)")
        ->check(sizeCheck());
    auto* half = command.add_flag("--half", options.half,
                                  "store colour channels as 16-bit half (default for 8-bit sources: exact for them)");
    command.add_flag("--float", options.full,
                     "store colour channels as 32-bit float (default for 16-bit and float sources)")
        ->excludes(half);
    addCompressionOption(command, options.compression);
    addBackendOption(command, options.backend, cpuPath);
}

Size conusSize(const StorageOptions& options, const Image& source) {
    if (!options.sizeText.empty()) return parseSize(options.sizeText);
    const auto [width, height] = codec::defaultConusSize(source.width, source.height);
    return {width, height};
}

void applyStorage(const StorageOptions& options, format::ConusFile& file) {
    // Half holds 11 significant bits: every 8-bit sRGB code survives the round trip, 16-bit ones do not.
    const std::optional<SampleType> source = file.sourceEncoding.sampleType;
    const bool precise = source && *source != SampleType::Uint8 && *source != SampleType::Half;
    file.pixelType = options.full || (precise && !options.half) ? format::PixelType::Float : format::PixelType::Half;
    file.compression = parseEnum<format::Compression>(options.compression);
}

void checkConusOutput(const std::string& output, const std::string& input) {
    try {
        format::checkConusFileName(output);
    } catch (const Error& e) {
        throw Error(e.code(), std::string(e.what()) + " (for a picture of it, run `conus decode` on the .exr)");
    }
    const std::string inputs[] = {input};
    checkOutputPath(output, inputs);
}

void addFitOption(CLI::App& command, FitSetting& fit, bool byDefault) {
    command.add_option("--filter", fit.filter,
                       "how each CoNUS pixel is filtered from the source: anisotropic (a few taps along the footprint's "
                       "long axis on the pyramid level of its short one, as GPUs do: the fast default) or ewa (every tap "
                       "over the footprint). Acts on the CPU encoder under a non-uniform map only: the GL encoder "
                       "always filters as ewa, and a uniform map (conus uniform) always takes the exact area average")
        ->check(CLI::IsMember(enumNames<codec::EncodeFilter>(), CLI::ignore_case))
        ->capture_default_str();
    CLI::Option* enabled = command.add_flag(
        "--fit", fit.enabled,
        std::string(byDefault ? "(the default) " : "") +
            "fit the CoNUS image to the decoder (--fit-method), from the filtered encode, so that the decoded "
            "view at the source's size comes closer to the source (the decoder's bilinear and multi-tap paths; "
            "zoomed-out views through the pyramid and the viewer reconstruct a little differently; colour and alpha "
            "are fitted, unclamped)");
    const std::string with = byDefault ? "" : "with --fit: ";
    CLI::Option* method =
        command
            .add_option("--fit-method", fit.method,
                        with + "local (one pass over the CoNUS image: the encode-then-decode kernel inverted, "
                               "held where the encoder low-passed) or least-squares (CGLS through the decoder at the "
                               "source's size, --fit-iterations passes)")
            ->check(CLI::IsMember(enumNames<codec::FitMethod>(), CLI::ignore_case))
            ->capture_default_str();
    CLI::Option* iterations = command.add_option("--fit-iterations", fit.iterations, with + "how many least-squares iterations")
                                  ->capture_default_str()
                                  ->type_name("N")
                                  ->check(CLI::Range(1, 100));
    CLI::Option* hold =
        command
            .add_option("--fit-hold", fit.hold,
                        with + "how strongly the fit keeps the encoder's low-pass along long, thin footprints (the "
                               "focus rims, where undoing it brings back a radial comb); 0: the plain least squares, sharper and "
                               "with more aliasing (default " + std::to_string(codec::kFitHoldLowPass).substr(0, 3) + ")")
            ->check(finiteRange(0.0, 1000.0, true, true));
    if (!byDefault) {
        method->needs(enabled);
        iterations->needs(enabled);
        hold->needs(enabled);
    }
}

namespace {

// What a fit achieved, for the line that says what was written (empty when nothing was fitted).
std::string fitText(const codec::FitResult& r) {
    if (r.steps.empty()) return {};
    // Overshoot at hard edges is kept, not clamped (the decoder interpolates it away): say how much.
    char text[200];
    std::snprintf(text, sizeof text,
                  "fitted to the decoder: decoded PSNR %.2f -> %.2f dB in %d iterations; %lld values below 0 "
                  "(lowest %.3g), kept",
                  r.steps.front().psnr, r.steps.back().psnr, r.steps.back().iteration, static_cast<long long>(r.negatives),
                  r.minimum);
    return text;
}

std::string encodeStage(int width, int height, Size size, const std::string& what) {
    return "encode " + std::to_string(width) + "x" + std::to_string(height) + " -> " + std::to_string(size.width) + "x" +
           std::to_string(size.height) + (what.empty() ? "" : ": " + what);
}

}  // namespace

format::ConusFile encodeToConus(const renderers::Device& device, const Image& source, const SourceEncoding& encoding,
                                const codec::SamplingMap& map, Size size, std::optional<format::AnalyticMap> analytic,
                                const FitSetting& fit, std::string* fitNote, const std::string& what,
                                codec::EncodeLevels* keptLevels) {
    Progress progress(encodeStage(source.width, source.height, size, what) + (device.onGpu() ? " (" + device.describe() + ")" : ""));
    std::vector<float> share;
    Image image =
        renderers::encodeImage(device, source, map, {size.width, size.height, 0, progress.callback(),
                                                   parseEnum<codec::EncodeFilter>(fit.filter), keptLevels, &share});
    progress.done();
    if (fit.count() > 0) {
        codec::FitOptions options;
        options.lowPassShare = &share;
        options.method = parseEnum<codec::FitMethod>(fit.method);
        const bool local = options.method == codec::FitMethod::Local;
        Progress fitting(local ? std::string("fit to the decoder (local)")
                               : "fit to the decoder (" + std::to_string(fit.count()) + " iterations)");
        options.iterations = fit.count();
        options.holdLowPass = fit.hold;
        options.progress = fitting.callback();
        const codec::FitResult r = codec::fitToDecoder(source, map, image, options);
        fitting.done();
        if (fitNote) *fitNote = fitText(r);
    }
    return codec::makeImageFile(std::move(image), map, source.width, source.height, encoding, std::move(analytic));
}

format::ConusFile keptEncodeToConus(const codec::ModelEncode& kept, const SourceEncoding& encoding, const codec::SamplingMap& map,
                                    int sourceWidth, int sourceHeight, std::optional<format::AnalyticMap> analytic,
                                    std::string* fitNote) {
    if (fitNote) *fitNote = fitText(kept.fit);
    return codec::makeImageFile(kept.image, map, sourceWidth, sourceHeight, encoding, std::move(analytic));
}

format::ConusFile encodeToConus(const renderers::Device& device, const codec::EightBitImage& source, const SourceEncoding& encoding,
                                const codec::SamplingMap& map, Size size, std::optional<format::AnalyticMap> analytic,
                                const FitSetting& fit, std::string* fitNote, const std::string& what) {
    if (device.onGpu() || fit.count() > 0)
        return encodeToConus(device, codec::linearImage(source), encoding, map, size, std::move(analytic), fit, fitNote, what);
    Progress progress(encodeStage(source.width, source.height, size, what));
    Image image = codec::encodeImage(source, map, {size.width, size.height, 0, progress.callback(), parseEnum<codec::EncodeFilter>(fit.filter)});
    progress.done();
    return codec::makeImageFile(std::move(image), map, source.width, source.height, encoding, std::move(analytic));
}

}  // namespace conus::cli
