// NRRD through teem: the one file of CoNUS that includes a teem header. Before teem opens
// anything, the header's text is scanned for its data files, each checked by the policy of
// named_files.h (a detached header may not name /etc/passwd, /dev/zero or a FIFO). Then the header
// is read without the data (teem's skipData), so that the declared size (teem's buffer of the
// file's type plus the float samples) and the payload's length are checked before teem allocates
// for the samples; teem then reads and decodes the payload (raw, ascii, gzip, ...).
#include <teem/nrrd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "conus/core/error.h"
#include "conus/sceneio/named_files.h"
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

// The header's text: the lines up to the first blank one (attached data follows it) or the end.
struct HeaderText {
    std::vector<std::string> lines;
    std::uint64_t bytes = 0;  // through the blank line: where attached data starts
};

HeaderText headerText(const std::string& path, const std::string& what) {
    constexpr std::uint64_t kMaxHeaderBytes = 1 << 20;
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::Io, what + ": cannot open it");
    HeaderText header;
    for (std::string line; std::getline(in, line);) {
        header.bytes += line.size() + 1;
        if (header.bytes > kMaxHeaderBytes)
            throw Error(ErrorCode::Corrupt, what + ": no end of the header in its first " + std::to_string(kMaxHeaderBytes) + " bytes");
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) break;
        header.lines.push_back(line);
    }
    return header;
}

// The data files the header names ("data file: NAME", "data file: LIST" followed by one name a
// line), each resolved and checked by `named`; none for attached data. The numbered form
// ("data file: FORMAT MIN MAX STEP") is refused: its names are not listed to check.
std::vector<std::string> dataFiles(const HeaderText& header, const NamedFiles& named, const std::string& what) {
    std::vector<std::string> files;
    for (std::size_t i = 1; i < header.lines.size(); ++i) {
        const std::string& line = header.lines[i];
        std::string value;
        if (line.rfind("data file:", 0) == 0) value = line.substr(10);
        else if (line.rfind("datafile:", 0) == 0) value = line.substr(9);
        else continue;
        const auto first = value.find_first_not_of(" \t");
        value = first == std::string::npos ? std::string() : value.substr(first);
        std::istringstream words(value);
        std::vector<std::string> tokens;
        for (std::string w; words >> w;) tokens.push_back(w);
        if (!tokens.empty() && tokens[0] == "LIST") {
            for (std::size_t k = i + 1; k < header.lines.size(); ++k) files.push_back(named.resolve(header.lines[k]));
            break;
        }
        if (tokens.size() >= 4 && tokens[0].find('%') != std::string::npos)
            throw Error(ErrorCode::Unsupported, what + ": a numbered data file pattern ('" + value +
                                                    "') is not read; name the files with 'data file: LIST'");
        files.push_back(named.resolve(value));
    }
    return files;
}

}  // namespace

Volume readNrrdVolume(const std::string& path, const VolumeReadOptions& options) {
    const std::string what = "nrrd volume '" + path + "'";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(ErrorCode::Io, what + ": no such file");
    const HeaderText header = headerText(path, what);
    const std::vector<std::string> files = dataFiles(header, NamedFiles(path, options.allowedDirs, what), what);
    std::uint64_t dataBytes = 0;
    if (files.empty()) {
        const std::uint64_t size = std::filesystem::file_size(path, ec);
        dataBytes = size > header.bytes ? size - header.bytes : 0;
    }
    for (const std::string& file : files) dataBytes += std::filesystem::file_size(file, ec);

    std::unique_ptr<Nrrd, NrrdDeleter> nrrd(nrrdNew());
    std::string encoding = "raw";
    {
        std::unique_ptr<NrrdIoState, IoDeleter> io(nrrdIoStateNew());
        io->skipData = AIR_TRUE;
        if (nrrdLoad(nrrd.get(), path.c_str(), io.get()))
            throw Error(ErrorCode::Corrupt, what + ": " + teemError());
        if (io->encoding) encoding = io->encoding->name;
    }
    if (nrrd->dim != 3)
        throw Error(ErrorCode::Unsupported, what + ": " + std::to_string(nrrd->dim) + "-D; a volume is 3-D");
    if (nrrd->type == nrrdTypeBlock || nrrd->type <= nrrdTypeUnknown || nrrd->type > nrrdTypeDouble)
        throw Error(ErrorCode::Unsupported, what + ": its sample type is not a scalar number");
    const std::int64_t sides[3] = {std::int64_t(nrrd->axis[0].size), std::int64_t(nrrd->axis[1].size),
                                   std::int64_t(nrrd->axis[2].size)};
    checkDimensions(what, sides[0], sides[1], sides[2], options.maxVoxels);
    // teem holds the samples in the file's type while they are converted to float.
    const std::uint64_t voxels = std::uint64_t(sides[0] * sides[1] * sides[2]);
    const std::uint64_t declared = voxels * nrrdTypeSize[nrrd->type];
    if (declared + voxels * sizeof(float) > std::uint64_t(kMaxVolumeReadBytes))
        throw Error(ErrorCode::LimitExceeded, what + ": reading " + std::to_string(voxels) + " samples of " +
                                                  std::to_string(nrrdTypeSize[nrrd->type]) + " bytes as float takes " +
                                                  std::to_string(declared + voxels * sizeof(float)) +
                                                  " bytes, more than the limit of " + std::to_string(kMaxVolumeReadBytes));
    // The least payload each encoding needs for the declared samples (deflate expands at most 1032
    // times; an ascii value takes a character, a hex byte two).
    const std::uint64_t least = encoding == "raw"     ? declared
                                : encoding == "gzip"  ? declared / 1032
                                : encoding == "ascii" ? voxels
                                : encoding == "hex"   ? declared * 2
                                                      : 0;
    if (dataBytes < least)
        throw Error(ErrorCode::Corrupt, what + ": holds " + std::to_string(dataBytes) + " bytes of " + encoding +
                                            " data; its header's " + std::to_string(voxels) + " samples need at least " +
                                            std::to_string(least));

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
    checkFileVolume(volume, what);
    return volume;
}

}  // namespace conus::sceneio
