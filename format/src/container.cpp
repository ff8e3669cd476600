// The public container entry points: validate, then write atomically; load, then throw or report.
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
                    "refusing to write invalid CoNUS file " + path + ": " + report.summary());
    }
    AtomicFile out(path);
    detail::writeExrFile(out, file);
    out.commit();
}

ConusFile readConusFile(const std::string& path, const ReadLimits& limits) {
    ConusFile file;
    const detail::LoadResult result = detail::loadConusFile(path, limits, file);
    if (!result.report.ok()) throw Error(result.code, path + ": " + result.report.summary());
    return file;
}

ValidationReport validateConusFile(const std::string& path, const ReadLimits& limits) {
    ConusFile file;
    return detail::loadConusFile(path, limits, file).report;
}

}  // namespace conus::format
