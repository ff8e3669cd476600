// The public container entry points: validate, then write atomically; load, then throw or report.
#include "conus/format/container.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "conus/core/atomic_file.h"
#include "conus/format/exr_check.h"
#include "conus/format/reflection_asset.h"
#include "exr_io_pvt.h"
#include "header_model_pvt.h"

namespace conus::format {

namespace {

bool onlyMapRules(const ValidationReport& r) {
    for (const Issue& issue : r.issues) {
        if (number(issue.rule) < 8 || number(issue.rule) > 11) return false;
    }
    return true;
}

}  // namespace

namespace detail {

CameraCheck describeCamera(const CameraAttributes& a) {
    const std::optional<Projection> projection = tryParseEnum<Projection>(a.projection);
    if (!projection) return {std::nullopt, "projection `" + a.projection + "` is not one of " + enumChoices<Projection>()};
    try {
        return {Camera::fromMatrices(a.worldToCamera, a.worldToNDC, *projection), {}};
    } catch (const Error& e) {
        return {std::nullopt, e.what()};
    }
}

}  // namespace detail

conus::Camera toCamera(const CameraAttributes& attributes) {
    detail::CameraCheck check = detail::describeCamera(attributes);
    if (!check.camera) throw Error(ErrorCode::Corrupt, "the file's camera (rule " + label(Rule::V13) + ") describes none: " + check.problem);
    return std::move(*check.camera);
}

CameraAttributes toAttributes(const conus::Camera& camera) {
    return {enumName(camera.projection()), camera.worldToCamera(), camera.worldToNDC()};
}

namespace {

// Validates `what`, then writes it through an AtomicFile: nothing under `path` unless all of it.
template <class File>
void writeValid(const std::string& path, const File& what, const ValidationReport& report, const char* kind) {
    if (!report.ok()) {
        throw Error(onlyMapRules(report) ? ErrorCode::InvalidMap : ErrorCode::Corrupt,
                    std::string("refusing to write invalid ") + kind + " " + path + ": " + report.summary(), report.ruleNumbers());
    }
    AtomicFile out(path);
    detail::writeExrFile(out, what);
    out.commit();
}

}  // namespace

void writeConusFile(const std::string& path, const ConusFile& file) {
    writeValid(path, file, validateConusFile(file), "CoNUS file");
}

void writeReflectionAsset(const std::string& path, const ReflectionAssetFile& asset) {
    writeValid(path, asset, validateReflectionAsset(asset), "reflection asset");
}

void checkConusFileName(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
    if (extension != ".exr")
        throw Error(ErrorCode::InvalidArgument, "the output " + path + " must end in .exr: a CoNUS file is an OpenEXR file");
}

namespace {

// A file that cannot be opened (missing, a directory, unreadable) breaks no rule a reader would
// look up: its message alone, which names the file ("cannot open x.exr: no such file"); a file
// that opens but breaks rules names them (`validate` lists every one).
void throwIfRefused(const detail::LoadResult& result, const std::string& path) {
    if (result.report.ok()) return;
    if (result.code == ErrorCode::Io) throw Error(result.code, result.report.issues.front().message);
    throw Error(result.code, path + ": " + result.report.summary(), result.report.ruleNumbers());
}

ConusFile load(const std::string& path, const Limits& limits, bool readPixels) {
    ConusFile file;
    throwIfRefused(detail::loadConusFile(path, limits, readPixels, file), path);
    return file;
}

ReflectionAssetFile loadAsset(const std::string& path, const Limits& limits, bool readPixels) {
    ReflectionAssetFile asset;
    throwIfRefused(detail::loadReflectionAsset(path, limits, readPixels, asset), path);
    return asset;
}

}  // namespace

ConusFile readConusFile(const std::string& path, const Limits& limits) { return load(path, limits, true); }

ConusFile readConusHeader(const std::string& path, const Limits& limits) { return load(path, limits, false); }

ReflectionAssetFile readReflectionAsset(const std::string& path, const Limits& limits) { return loadAsset(path, limits, true); }

ReflectionAssetFile readReflectionAssetHeader(const std::string& path, const Limits& limits) {
    return loadAsset(path, limits, false);
}

bool isReflectionAsset(const std::string& path) { return detail::hasReflectionLayout(path); }

ValidationReport validateConusFile(const std::string& path, const Limits& limits, bool readPixels) {
    // The rules concern headers, the map and the chunk tables, never pixel values; reading the
    // pixels finds damaged compressed data, which only a decompression can see.
    return detail::validateFile(path, limits, readPixels).report;
}

void checkExrFile(const std::string& path, const Limits& limits) { detail::checkExr(path, limits); }

}  // namespace conus::format
