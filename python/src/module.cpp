// `import conus`: the toolkit over numpy (pybind11). The compiled part, conus._conus; the package
// (python/conus/__init__.py) re-exports it and adds the pure-Python helpers. Here: errors, File,
// read, write, encode, decode and the image calls; maps.cpp: Map and importance; scene.cpp: the
// scene readers; arguments.cpp: what users pass.
//
// Shared rules:
// - Pixels CoNUS returns are float32 numpy arrays of shape (height, width, channels), linear light,
//   channels named by the file (R, G, B, A, Y, Z, ...); what it takes follows arguments.h (float:
//   linear light; uint8/uint16: display codes, as a PNG's). Returned arrays own their memory
//   without a copy (a capsule holds the C++ image); File.pixels and Map.nodes are views into the
//   object they come from and keep it alive.
// - Every long call (read, write, encode, decode, building a map, distort/undistort of many
//   points) releases the GIL.
// - A conus::Error becomes conus.Error with .code ("corrupt", "limit-exceeded", ...), .rules (the
//   spec rules it breaks, by number) and .rule (the first, or None).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/foci_budget.h"
#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/builders/importance.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "conus/codec/image/metrics.h"
#include "conus/core/error.h"
#include "conus/format/container.h"
#include "conus/imageio/image_file.h"
#include "conus/renderers/gpu_image.h"
#include "arguments.h"
#include "foci_budget_info.h"
#include "maps.h"
#include "scene.h"

namespace py = pybind11;

namespace conus::python {
namespace {

// ---- errors ------------------------------------------------------------------------------------

PyObject* g_error = nullptr;  // conus.Error

const char* codeName(ErrorCode code) {
    switch (code) {
        case ErrorCode::InvalidArgument: return "invalid-argument";
        case ErrorCode::Io: return "io";
        case ErrorCode::NotConus: return "not-conus";
        case ErrorCode::Corrupt: return "corrupt";
        case ErrorCode::LimitExceeded: return "limit-exceeded";
        case ErrorCode::InvalidMap: return "invalid-map";
        case ErrorCode::Unsupported: return "unsupported";
    }
    return "unknown";
}

void translateError(std::exception_ptr p) {
    try {
        if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
        py::object error = py::reinterpret_borrow<py::object>(g_error)(e.what());
        error.attr("code") = codeName(e.code());
        error.attr("rules") = py::cast(e.rules());
        error.attr("rule") = e.rules().empty() ? py::object(py::none()) : py::object(py::int_(e.rules().front()));
        PyErr_SetObject(g_error, error.ptr());
    }
}

// ---- the objects -------------------------------------------------------------------------------

struct File {
    format::ConusFile file;
    std::optional<py::dict> budget;  // what encode(foci=...)'s budget did (foci_budget.h); none otherwise
    std::shared_ptr<Map> map;  // built from file.map on first use
    std::shared_ptr<Map> samplingMap() {
        if (!map)
            map = std::make_shared<Map>(Map{codec::SamplingMap::fromGrid(file.map), file.analytic, codec::madeForAspect(file)});
        return map;
    }
};

py::dict attributesOf(const format::ConusFile& f) {
    py::dict a;
    a["source_size"] = py::make_tuple(f.sourceWidth, f.sourceHeight);
    a["data_kind"] = enumName(f.dataKind);
    a["pixel_type"] = enumName(f.pixelType);
    a["compression"] = enumName(f.compression);
    a["software"] = f.software;
    a["transfer"] = enumName(f.sourceEncoding.transfer);
    if (f.sourceEncoding.sampleType) a["source_sample_type"] = enumName(*f.sourceEncoding.sampleType);
    if (f.analytic) {
        py::dict analytic;
        analytic["kind"] = f.analytic->kind;
        py::list foci;
        for (const format::FocusParams& p : f.analytic->foci) foci.append(py::make_tuple(p.u, p.v, p.r, p.k));
        analytic["foci"] = foci;
        analytic["composition"] = f.analytic->composition;
        analytic["scalars"] = f.analytic->scalars;
        a["analytic"] = analytic;
    }
    if (f.depth.kind != format::DepthKind::None) {
        py::dict depth;
        depth["kind"] = enumName(f.depth.kind);
        depth["units"] = f.depth.units;
        depth["near"] = f.depth.near;
        depth["far"] = f.depth.far;
        a["depth"] = depth;
    }
    return a;
}

// One GL context per backend for the process, used by one call at a time.
std::mutex g_deviceMutex;

const renderers::Device& deviceFor(const std::string& backend) {
    static std::map<std::string, renderers::Device> devices;
    auto it = devices.find(backend);
    if (it == devices.end())
        it = devices.emplace(backend, renderers::Device::choose(enumArgument<renderers::Backend>(backend, "backend"), renderers::CpuPath::Faster, "image encode and decode")).first;
    return it->second;
}

// The image's channels in the order people read them (R, G, B, A, ...; displayOrder), as an
// array's last axis should be: OpenEXR stores them sorted by name (A, B, G, R).
void toDisplayOrder(Image& image) {
    const std::vector<std::string> order = displayOrder(image.channels);
    if (order == image.channels) return;
    Image sorted = makeImage(image.width, image.height, order);
    std::vector<int> from;
    for (const std::string& name : order) from.push_back(image.channelIndex(name));
    const std::size_t n = std::size_t(image.width) * image.height, c = order.size();
    for (std::size_t p = 0; p < n; ++p)
        for (std::size_t k = 0; k < c; ++k) sorted.pixels[p * c + k] = image.pixels[p * c + std::size_t(from[k])];
    image = std::move(sorted);
}

// fit > 0: the encoded image fitted to its decoder with that many iterations (fit.h).
// `share`: the encode's low-pass share (EncodeOptions::lowPassShare), where it kept one.
void fitTo(const Image& source, const codec::SamplingMap& map, Image& encoded, int fit,
           double hold = codec::kFitHoldLowPass, const std::vector<float>* share = nullptr) {
    if (fit == 0) return;
    codec::FitOptions options;
    options.iterations = fit;
    options.holdLowPass = hold;
    options.lowPassShare = share;
    codec::fitToDecoder(source, map, encoded, options);
}

std::pair<int, int> sizeOr(const std::optional<std::pair<int, int>>& size, int w, int h) {
    return size ? *size : codec::defaultConusSize(w, h);
}

// A map made for pictures of another aspect stretches its foci into ellipses: say so.
void checkAspect(const Map& map, const Image& picture) {
    const double aspect = double(picture.width) / picture.height;
    if (!map.aspect || !codec::aspectsDiffer(*map.aspect, aspect)) return;
    char text[256];
    std::snprintf(text, sizeof text,
                  "the map was made for pictures of aspect %.3g (width / height) and this one's is %.3g: its foci become "
                  "ellipses (build it with aspect=%.3g)",
                  *map.aspect, aspect, aspect);
    warn(text);
}

// The pixel rules of an encode-like call (arguments.h).
PixelRules rulesOf(const std::string& colorspace, const std::string& fixNonFinite) { return {colorspace, fixNonFinite}; }

std::shared_ptr<Map> mapFrom(py::handle map) {
    if (map.is_none()) return nullptr;
    if (!py::isinstance<Map>(map))
        throw py::type_error("map must be a conus.Map (conus.Map.foci(...), conus.read(path).map), not " + describe(map));
    return map.cast<std::shared_ptr<Map>>();
}

}  // namespace
}  // namespace conus::python

PYBIND11_MODULE(_conus, m) {
    using namespace conus;
    using namespace conus::python;
    namespace codec = conus::codec;
    m.doc() = "CoNUS: coherent non-uniform sampling images (the compiled part of the conus package)";

    g_error = PyErr_NewExceptionWithDoc("conus.Error",
                                        "A CoNUS error: .code names its kind, .rules the spec rules it breaks, .rule the first",
                                        PyExc_RuntimeError, nullptr);
    m.attr("Error") = py::handle(g_error);
    py::register_exception_translator(&translateError);
    m.attr("MAX_IMAGE_SIDE") = kMaxImageSide;
    m.attr("MAX_MAP_SIDE") = kMaxMapSide;
    addSceneReaders(m);
    m.attr("DEFAULT_MAP_SIDE") = map_rules::kDefaultSide;

    addMaps(m);

    py::class_<File, std::shared_ptr<File>>(m, "File", "A CoNUS file in memory: the CoNUS image, its map and attributes")
        .def_property_readonly(
            "pixels",
            [](py::object self) {
                Image& image = self.cast<File&>().file.image;
                const py::ssize_t c = image.channelCount();
                return py::array_t<float>({py::ssize_t(image.height), py::ssize_t(image.width), c},
                                          {py::ssize_t(image.width) * c * 4, c * 4, py::ssize_t(4)}, image.pixels.data(), self);
            },
            "The CoNUS image, (height, width, channels) float32, a view")
        .def_property_readonly("channels", [](const File& self) { return self.file.image.channels; })
        .def_property_readonly("map", [](File& self) { return self.samplingMap(); })
        .def_property_readonly("attributes", [](const File& self) { return attributesOf(self.file); })
        .def_property_readonly("source_size", [](const File& self) { return py::make_tuple(self.file.sourceWidth, self.file.sourceHeight); })
        .def_property_readonly(
            "budget", [](const File& self) -> py::object { return self.budget ? py::object(*self.budget) : py::none(); },
            "What encode(foci=...)'s budget did, or None: k_asked, k_given (each focus's), lowered, frame_loss (the\n"
            "budget), tile_loss (its tiles' budget), predicted_frame_loss, predicted_tile_loss, predicted_roi_gain (dB;\n"
            "a negative loss is a gain; None where fit=0 leaves the model unconfirmed: the model alone overstates it),\n"
            "confirmed (whether an encode confirmed the model), predicted_frame_loss_exact_k and predicted_tile_loss_exact_k (what the k\n"
            "asked would hold: the price of exact_k=True), foci_share (of the CoNUS pixels),\n"
            "context_downscale and uniform_downscale (the linear downscale the context and the uniform image are\n"
            "sampled like), ask (the discs' pixels at k over all the pixels), grid_limited")
        .def("__repr__", [](const File& self) {
            const format::ConusFile& f = self.file;
            return "<conus.File " + std::to_string(f.image.width) + "x" + std::to_string(f.image.height) + " CoNUS image of a " +
                   std::to_string(f.sourceWidth) + "x" + std::to_string(f.sourceHeight) + " source, " +
                   std::to_string(f.map.columns) + "x" + std::to_string(f.map.rows) + " map>";
        });

    m.def(
        "read",
        [](const std::string& path) {
            auto file = std::make_shared<File>();
            py::gil_scoped_release release;
            file->file = format::readConusFile(path);
            toDisplayOrder(file->file.image);
            return file;
        },
        py::arg("path"), "Read a CoNUS file (every rule of the spec checked); channels in display order (R, G, B, A, ...)");
    m.def(
        "write",
        [](const std::string& path, const File& file) {
            try {
                format::checkConusFileName(path);
            } catch (const Error& e) {
                throw Error(e.code(), std::string(e.what()) + " (for a picture of it, conus.write_image(path, conus.decode(f)))");
            }
            py::gil_scoped_release release;
            format::writeConusFile(path, file.file);
        },
        py::arg("path"), py::arg("file"), "Write a CoNUS file (validated first, written atomically)");
    m.def(
        "encode",
        [](py::object pixels, py::object fociArgument, py::object sizeArgument, py::object mapArgument, py::object channels,
           const std::string& backend, py::object fitArgument, double fitHold, double frameLoss, bool exactK,
           const std::string& colorspace, const std::string& fixNonFinite) {
            const std::vector<codec::Focus> foci = fociFrom(fociArgument);
            const auto size = sizeFrom(sizeArgument);
            std::shared_ptr<Map> map = mapFrom(mapArgument);
            const int fit = iterationsFrom(fitArgument);
            Image source = pixelsFrom(pixels, channelsFrom(channels), "pixels", rulesOf(colorspace, fixNonFinite));
            if (!fociArgument.is_none() && map) throw Error(ErrorCode::InvalidArgument, "give foci or a map, not both");
            if (map) checkAspect(*map, source);
            const double aspect = double(source.width) / source.height;
            const auto [w, h] = sizeOr(size, source.width, source.height);
            if (map) codec::checkGridForImage(std::max(map->map.columns(), map->map.rows()), w, h, "the map's grid of");
            codec::checkEncodeMemory(source, w, h);  // before a map is built for it
            std::optional<codec::FociBudget> budget;
            // The budgets' model takes this encode's errors: on what a display shows (data as stored),
            // fitted or not; one real encode confirms it, but unfitted (fit=0, as `--fast`).
            const codec::FrameModelOptions trials{colorspace == enumName(Transfer::Raw) ? codec::ErrorSpace::Linear : codec::ErrorSpace::Display,
                                                  fit, fitHold, fit > 0};
            if (!map) {
                if (!foci.empty()) {
                    // The budget of `conus encode --focus` (foci_budget.h): k lowered to hold frame_loss,
                    // the foci on the context the picture's own detail asks for.
                    codec::FociMapRequest request;
                    request.model = trials;
                    request.frameLoss = frameLoss;
                    request.exactK = exactK;
                    std::optional<codec::FociMap> built;
                    {
                        py::gil_scoped_release release;
                        const Image detail = pictureImportance(codec::ImportanceRule::Detail, source);
                        request.detail = &detail;
                        built = codec::budgetedFociMap(source, foci, w, h, request);
                    }
                    budget = std::move(built->budget);
                    map = std::make_shared<Map>(Map{budget->map, std::move(built->analytic), aspect});
                } else {
                    // As `conus encode` with no focus, map or importance: the picture's own detail.
                    warn("conus.encode: no foci or map: the samples follow the picture's own detail (conus.importance(pixels, "
                         "'detail'), the context floor chosen for the whole frame); conus.uniform makes the uniform image");
                    py::gil_scoped_release release;
                    codec::BudgetResult own = codec::buildOwnDetailMap(
                        source, pictureImportance(codec::ImportanceRule::Detail, source), w, h, {}, trials);
                    map = std::make_shared<Map>(Map{std::move(own.map), {}, aspect});
                }
            }
            codec::EncodeOptions options;
            options.width = w;
            options.height = h;
            std::vector<float> share;
            options.lowPassShare = &share;
            auto file = std::make_shared<File>();
            {
                py::gil_scoped_release release;
                Image encoded;
                const bool onCpu = enumArgument<renderers::Backend>(backend, "backend") == renderers::Backend::Cpu;
                if (onCpu && budget && budget->encode) {
                    encoded = budget->encode->image;  // the budget's confirming encode of this map, fitted as asked: kept
                } else {
                    if (onCpu) {
                        encoded = codec::encodeImage(source, map->map, options);
                    } else {
                        std::lock_guard<std::mutex> lock(g_deviceMutex);
                        encoded = renderers::encodeImage(deviceFor(backend), source, map->map, options);
                    }
                    fitTo(source, map->map, encoded, fit, fitHold, &share);
                }
                file->file = codec::makeImageFile(std::move(encoded), map->map, source.width, source.height, SourceEncoding{},
                                                  map->analytic);
            }
            file->map = map;
            if (budget) file->budget = budgetInfo(*budget, frameLoss, w, h, source.width, source.height, trials.confirm);
            return file;
        },
        py::arg("pixels"), py::arg("foci") = py::none(), py::arg("size") = py::none(), py::arg("map") = py::none(),
        py::arg("channels") = py::none(), py::arg("backend") = enumName(renderers::Backend::Cpu), py::arg("fit") = codec::kDefaultEncodeFitIterations,
        py::arg("fit_hold") = codec::kFitHoldLowPass, py::arg("frame_loss") = codec::kDefaultFrameLoss, py::arg("exact_k") = false,
        py::arg("colorspace") = kAutoColorspace, py::arg("fix_nonfinite") = enumName(imageio::NonFiniteRepair::Keep),
        "Encode pixels (H, W) or (H, W, C) through foci [(u, v, r, k)] or a Map into a CoNUS file; float pixels are\n"
        "linear light, uint8/uint16 display-encoded codes (colorspace= 'srgb' or 'linear' overrides; docs/python.md);\n"
        "fix_nonfinite 'keep' (with a warning), 'black' or 'box3' as --fix-nonfinite;\n"
        "size (w, h) defaults to a quarter of each side; backend 'cpu', 'auto', 'egl' or 'osmesa'. As `conus encode`:\n"
        "foci hold a whole-frame loss budget (frame_loss dB, predicted) by lowering every k alike, with a\n"
        "UserWarning that says so (exact_k=True keeps k; the File's .budget says what was given); with neither\n"
        "foci nor a map the samples follow the picture's own detail (with a UserWarning); fit = N\n"
        "least-squares iterations fit the image to the decoder (default 2; 0: the filtered encode alone, `--fast`);\n"
        "fit_hold: its damping where the encoder low-passed a long footprint axis (`--fit-hold`)");
    m.def(
        "decode",
        [](py::object fileArgument, py::object viewArgument, py::object sizeArgument, const std::string& backend) {
            if (!py::isinstance<File>(fileArgument))
                throw py::type_error("file must be a conus.File (from conus.read(path) or conus.encode(...)), not " +
                                     describe(fileArgument));
            File& file = fileArgument.cast<File&>();
            const codec::View view = viewFrom(viewArgument);
            const auto size = sizeFrom(sizeArgument);
            const auto [u0, v0, u1, v1] = view;
            codec::DecodeOptions options;
            options.view = view;
            if (size) {
                options.width = size->first;
                options.height = size->second;
            } else {
                options.width = std::max(1, int(std::lround(std::abs(u1 - u0) * file.file.sourceWidth)));
                options.height = std::max(1, int(std::lround(std::abs(v1 - v0) * file.file.sourceHeight)));
            }
            const std::shared_ptr<Map> map = file.samplingMap();
            Image frame;
            {
                py::gil_scoped_release release;
                if (enumArgument<renderers::Backend>(backend, "backend") == renderers::Backend::Cpu) {
                    frame = codec::decodeImage(file.file.image, map->map, options);
                } else {
                    std::lock_guard<std::mutex> lock(g_deviceMutex);
                    frame = renderers::decodeImage(deviceFor(backend), file.file.image, map->map, options);
                }
            }
            return toArray(std::move(frame));
        },
        py::arg("file"), py::arg("view") = std::make_tuple(0.0, 0.0, 1.0, 1.0), py::arg("size") = py::none(), py::arg("backend") = enumName(renderers::Backend::Cpu),
        "A conventional frame of the rectangle view (u0, v0, u1, v1), at size (w, h) (default: the source's resolution)");
    m.def(
        "uniform",
        [](py::object pixels, py::object sizeArgument, py::object fitArgument, const std::string& colorspace,
           const std::string& fixNonFinite, py::object channels) {
            const auto size = sizeFrom(sizeArgument);
            const int fit = iterationsFrom(fitArgument);
            Image source = pixelsFrom(pixels, channelsFrom(channels), "pixels", rulesOf(colorspace, fixNonFinite));
            const auto [w, h] = sizeOr(size, source.width, source.height);
            codec::checkEncodeMemory(source, w, h);
            auto file = std::make_shared<File>();
            {
                // As `conus uniform`: the encode through the identity map, fitted as --fit says.
                py::gil_scoped_release release;
                const codec::SamplingMap identity = codec::SamplingMap::identity(2, 2);
                codec::EncodeOptions options;
                options.width = w;
                options.height = h;
                Image small = codec::encodeImage(source, identity, options);
                fitTo(source, identity, small, fit);
                file->file = codec::makeImageFile(std::move(small), identity, source.width, source.height, SourceEncoding{}, std::nullopt);
            }
            return file;
        },
        py::arg("pixels"), py::arg("size") = py::none(), py::arg("fit") = 0, py::arg("colorspace") = kAutoColorspace,
        py::arg("fix_nonfinite") = enumName(imageio::NonFiniteRepair::Keep), py::arg("channels") = py::none(),
        "The uniform baseline as `conus uniform` makes it: a conus.File of the same pixel count through the identity map\n"
        "(pixels as for encode; size (w, h) defaults to a quarter of each side), to write or decode like any other;\n"
        "fit = N > 0 fits it to its decoder (`conus uniform --fit --fit-iterations N`)");
    m.def(
        "resize",
        [](py::object pixels, py::object sizeArgument) {
            const auto given = sizeFrom(sizeArgument);
            if (!given) throw py::type_error("size must be (width, height) in whole pixels, such as (512, 384), not None");
            const std::pair<int, int> size = *given;
            Image source = pixelsFrom(pixels, std::nullopt, "pixels");
            py::gil_scoped_release release;
            Image out = codec::resizeBilinear(source, {}, size.first, size.second);
            py::gil_scoped_acquire acquire;
            return toArray(std::move(out));
        },
        py::arg("pixels"), py::arg("size"), "Bilinear resize (how a uniform image is shown at another size)");
    m.def(
        "psnr", [](py::object a, py::object b, double peak) {
            return codec::psnr(pixelsFrom(a, std::nullopt, "a"), pixelsFrom(b, std::nullopt, "b"), peak);
        },
        py::arg("a"), py::arg("b"), py::arg("peak") = 1.0, "PSNR in dB of two images of the same shape");
    m.def(
        "read_image",
        [](const std::string& path) {
            imageio::ImageFile file;
            {
                py::gil_scoped_release release;
                file = imageio::readImageFile(path);
            }
            py::list channels = py::cast(file.image.channels);
            return py::make_tuple(toArray(std::move(file.image)), channels);
        },
        py::arg("path"), "Read an ordinary picture (PNG, JPEG, TIFF, EXR, ...) as linear float: (pixels, channels)");
    m.def(
        "write_image",
        [](const std::string& path, py::object pixels, py::object channels, const std::string& colorspace,
           const std::string& fixNonFinite) {
            Image image = pixelsFrom(pixels, channelsFrom(channels), "pixels", rulesOf(colorspace, fixNonFinite));
            py::gil_scoped_release release;
            imageio::writeImageFile(path, image);
        },
        py::arg("path"), py::arg("pixels"), py::arg("channels") = py::none(), py::arg("colorspace") = kAutoColorspace,
        py::arg("fix_nonfinite") = enumName(imageio::NonFiniteRepair::Keep),
        "Write pixels (as for encode: float linear light, uint8/uint16 display codes) as an ordinary picture (8-bit\n"
        "sRGB for PNG/JPEG, half for EXR), atomically");
}
