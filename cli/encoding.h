// What `encode`, `uniform` and `demo` share: options for how a CoNUS file is stored, and the one
// path from a source image and a map to a ConusFile.
#pragma once

#include <optional>
#include <string>

#include "arguments.h"
#include "backend.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"

namespace conus::codec {
struct ModelEncode;
}

namespace CLI {
class App;
}

namespace conus::cli {

struct StorageOptions {
    std::string sizeText;  // "WxH"; empty: a quarter of each source side (1/16 of the pixels)
    bool half = false, full = false;  // neither: float for 16-bit and float sources, else half
    std::string compression = enumName(format::Compression::Zip);
    std::string backend = enumName(renderers::Backend::Auto);
};

void addStorageOptions(CLI::App& command, StorageOptions& options,
                       renderers::CpuPath cpuPath = renderers::CpuPath::Faster);

// Resolves the CoNUS image size (checking it against the source) and the storage settings.
Size conusSize(const StorageOptions& options, const Image& source);

// Adds --filter, --fit, --fit-iterations N and --fit-hold H (encode and uniform alike, so that comparisons
// can be like for like). --fit is a plain flag (an optional count after it would take the input's name when
// written first); --fit-iterations and --fit-hold need it.
struct FitSetting {
    std::string filter = enumName(codec::EncodeFilter::Anisotropic);  // --filter: the encode before any fit
    bool enabled = false;
    std::string method = enumName(codec::FitMethod::LeastSquares);  // --fit-method
    int iterations = codec::kFitIterations;
    double hold = codec::kFitHoldLowPass;
    int count() const { return enabled ? iterations : 0; }  // iterations to run; 0: the filtered encode alone
};
// `encode` fits by default (the sharpest picture it makes; --fast leaves the fit out): then --fit
// only says so, and --fit-iterations and --fit-hold stand alone.
inline FitSetting defaultFit() {
    FitSetting fit;
    fit.enabled = true;
    fit.method = enumName(codec::kDefaultEncodeFitMethod);
    fit.iterations = codec::kDefaultEncodeFitIterations;
    return fit;
}
void addFitOption(CLI::App& command, FitSetting& fit, bool byDefault = false);

// Encodes `source` through `map` at `size` (with progress) into a file model ready to write,
// remembering the source's encoding. fit.iterations > 0 then fits the image to the decoder with that many
// iterations (codec/image/fit.h) and, when `fitNote` is given, says what the fit achieved there.
// `what`, when given, says in the stage's line which image this is (a command that encodes two).
// `keptLevels`: the CPU encoder's levels of this source kept between calls (codec::EncodeLevels).
format::ConusFile encodeToConus(const renderers::Device& device, const Image& source, const SourceEncoding& encoding,
                                const codec::SamplingMap& map, Size size, std::optional<format::AnalyticMap> analytic,
                                const FitSetting& fit = {}, std::string* fitNote = nullptr, const std::string& what = {},
                                codec::EncodeLevels* keptLevels = nullptr);

// The same file from an encode already made of `map` (a budget's confirming encode, kept:
// codec::ModelEncode, encoded and fitted as `encode` asks), with the same note on its fit.
format::ConusFile keptEncodeToConus(const codec::ModelEncode& kept, const SourceEncoding& encoding, const codec::SamplingMap& map,
                                    int sourceWidth, int sourceHeight, std::optional<format::AnalyticMap> analytic,
                                    std::string* fitNote = nullptr);
// The same of a picture kept as 8-bit codes: the CPU encoder reads them (codec::encodeImage of
// an EightBitImage); the GL encoder and the fit take the linear picture they stand for.
format::ConusFile encodeToConus(const renderers::Device& device, const codec::EightBitImage& source, const SourceEncoding& encoding,
                                const codec::SamplingMap& map, Size size, std::optional<format::AnalyticMap> analytic,
                                const FitSetting& fit = {}, std::string* fitNote = nullptr, const std::string& what = {});

// Applies the storage options to a file model. Without --half or --float, colour is stored as
// float when the source had more precision than half keeps (16-bit integers, float), else half.
void applyStorage(const StorageOptions& options, format::ConusFile& file);

// Checks before the work that `output` is a place for a CoNUS file: an .exr name that is not
// the input. Throws conus::Error(InvalidArgument).
void checkConusOutput(const std::string& output, const std::string& input);

}  // namespace conus::cli
