// NRRD through teem: the one file of CoNUS that includes a teem header. The header is read first
// without the data (teem's skipData), so the declared size is checked against the caps before
// teem allocates for the samples; teem then reads and decodes the payload (raw, ascii, gzip, ...)
// and reports a payload shorter than its header declares.
#include <teem/nrrd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

#include "conus/core/error.h"
#include "conus/sceneio/volume_file.h"

namespace conus::sceneio {
namespace {

struct NrrdDeleter {
    void operator()(Nrrd* n) const { nrrdNuke(n); }
};
struct IoDeleter {
    void operator()(NrrdIoState* n) const { nrrdIoStateNix(n); }
};

// teem's error messages collect in its "biff" under the library's key; take and free them.
std::string teemError() {
    char* text = biffGetDone(NRRD);
    std::string out = text ? text : "unknown teem error";
    std::free(text);
    return out;
}

// A spacing teem knows for axis `axis` (its spacing, or the length of its space direction), 1 when
// the header gives none.
double axisSpacing(const Nrrd* nrrd, unsigned axis) {
    double spacing = 1.0;
    double vector[NRRD_SPACE_DIM_MAX];
    const int status = nrrdSpacingCalculate(nrrd, axis, &spacing, vector);
    if (status == nrrdSpacingStatusScalarNoSpace || status == nrrdSpacingStatusScalarWithSpace) return spacing;
    if (status == nrrdSpacingStatusDirection) return nrrdSpaceVecNorm(nrrd->spaceDim, vector);
    return 1.0;
}

}  // namespace

Volume readNrrdVolume(const std::string& path, const VolumeReadOptions& options) {
    const std::string what = "nrrd volume '" + path + "'";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(ErrorCode::Io, what + ": no such file");

    std::unique_ptr<Nrrd, NrrdDeleter> nrrd(nrrdNew());
    {
        std::unique_ptr<NrrdIoState, IoDeleter> io(nrrdIoStateNew());
        io->skipData = AIR_TRUE;
        if (nrrdLoad(nrrd.get(), path.c_str(), io.get()))
            throw Error(ErrorCode::Corrupt, what + ": " + teemError());
    }
    if (nrrd->dim != 3)
        throw Error(ErrorCode::Unsupported, what + ": " + std::to_string(nrrd->dim) + "-D; a volume is 3-D");
    if (nrrd->type == nrrdTypeBlock || nrrd->type <= nrrdTypeUnknown || nrrd->type > nrrdTypeDouble)
        throw Error(ErrorCode::Unsupported, what + ": its sample type is not a scalar number");
    const std::int64_t sides[3] = {std::int64_t(nrrd->axis[0].size), std::int64_t(nrrd->axis[1].size),
                                   std::int64_t(nrrd->axis[2].size)};
    checkDimensions(what, sides[0], sides[1], sides[2], options.maxVoxels);

    nrrd.reset(nrrdNew());
    if (nrrdLoad(nrrd.get(), path.c_str(), nullptr)) throw Error(ErrorCode::Corrupt, what + ": " + teemError());
    // The file may have changed between the two reads: check again what was read.
    if (nrrd->dim != 3 || std::int64_t(nrrd->axis[0].size) != sides[0] || std::int64_t(nrrd->axis[1].size) != sides[1] ||
        std::int64_t(nrrd->axis[2].size) != sides[2] || nrrd->type == nrrdTypeBlock || !nrrd->data)
        throw Error(ErrorCode::Corrupt, what + ": changed while it was read");

    Volume volume;
    volume.width = int(sides[0]);
    volume.height = int(sides[1]);
    volume.depth = int(sides[2]);
    volume.spacing = {axisSpacing(nrrd.get(), 0), axisSpacing(nrrd.get(), 1), axisSpacing(nrrd.get(), 2)};
    const std::size_t count = static_cast<std::size_t>(sides[0] * sides[1] * sides[2]);
    volume.values.resize(count);
    double (*lookup)(const void*, size_t) = nrrdDLookup[nrrd->type];
    for (std::size_t i = 0; i < count; ++i) volume.values[i] = static_cast<float>(lookup(nrrd->data, i));
    checkVolume(volume, what);
    return volume;
}

}  // namespace conus::sceneio
