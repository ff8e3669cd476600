// The public container entry points: validate, then write atomically; load, then throw or report.
#include <filesystem>
#include <system_error>

#include <unistd.h>

#include "conus/format/container.h"
#include "exr_io.h"

namespace conus::format {

namespace {

bool onlyMapRules(const ValidationReport& r) {
    for (const Issue& issue : r.issues) {
        if (issue.rule < 8 || issue.rule > 11) return false;
    }
    return true;
}

}  // namespace

void writeConusFile(const std::string& path, const ConusFile& file) {
    const ValidationReport report = validateConusFile(file);
    if (!report.ok()) {
        throw Error(onlyMapRules(report) ? ErrorCode::InvalidMap : ErrorCode::Corrupt,
                    "refusing to write invalid CoNUS file " + path + ": " + report.str());
    }
    // Write beside the destination and rename: a reader never sees a half-written file and an
    // existing destination survives any failure. The pid keeps concurrent writers apart.
    const std::string temp = path + ".tmp-" + std::to_string(::getpid());
    try {
        detail::writeExrFile(temp, file);
        std::error_code ec;
        std::filesystem::rename(temp, path, ec);
        if (ec) throw Error(ErrorCode::Io, "cannot rename " + temp + " to " + path + ": " + ec.message());
    } catch (...) {
        std::error_code ignored;
        std::filesystem::remove(temp, ignored);
        throw;
    }
}

namespace {

ConusFile load(const std::string& path, const ReadLimits& limits, bool readPixels) {
    ConusFile file;
    const detail::LoadResult result = detail::loadConusFile(path, limits, readPixels, file);
    if (!result.report.ok()) throw Error(result.code, path + ": " + result.report.str());
    return file;
}

}  // namespace

ConusFile readConusFile(const std::string& path, const ReadLimits& limits) { return load(path, limits, true); }

ConusFile readConusHeader(const std::string& path, const ReadLimits& limits) { return load(path, limits, false); }

ValidationReport validateConusFile(const std::string& path, const ReadLimits& limits) {
    // The rules concern headers, the map and the chunk tables, never pixel values: pixels are not read.
    ConusFile file;
    return detail::loadConusFile(path, limits, false, file).report;
}

}  // namespace conus::format
