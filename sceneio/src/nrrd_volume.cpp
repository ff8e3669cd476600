// NRRD through teem: the one file of CoNUS that includes a teem header. Before teem opens
// anything, the header's text is scanned for its data files, each checked by the policy of
// named_files.h (a detached header may not name /etc/passwd, /dev/zero or a FIFO). Then the header
// is read without the data (teem's skipData), so that the declared size (teem's buffer of the
// file's type plus the float samples) and the payload's length are checked before teem allocates
// for the samples; teem then reads and decodes the payload (raw, ascii, gzip, ...).
#include <teem/nrrd.h>

#include <algorithm>
#include <cctype>
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

// The header's text as teem reads it: a line ends at LF, CR or CR LF (teem's airOneLine), and the
// lines run up to the first empty one (attached data follows it) or the end.
struct HeaderText {
    std::vector<std::string> lines;
    std::uint64_t bytes = 0;  // through the empty line: where attached data starts
};

HeaderText headerText(const std::string& path, const std::string& what) {
    constexpr std::uint64_t kMaxHeaderBytes = 1 << 20;
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::Io, what + ": cannot open it");
    std::streambuf& bytes = *in.rdbuf();
    HeaderText header;
    std::string line;
    for (int c; (c = bytes.sbumpc()) != std::char_traits<char>::eof();) {
        if (++header.bytes > kMaxHeaderBytes)
            throw Error(ErrorCode::Corrupt, what + ": no end of the header in its first " + std::to_string(kMaxHeaderBytes) + " bytes");
        if (c != '\n' && c != '\r') {
            line += static_cast<char>(c);
            continue;
        }
        if (c == '\r' && bytes.sgetc() == '\n') {
            bytes.sbumpc();
            ++header.bytes;
        }
        if (line.empty()) return header;
        line.resize(std::min(line.size(), line.find('\0')));  // teem's line is a C string
        header.lines.push_back(std::move(line));
        line.clear();
    }
    line.resize(std::min(line.size(), line.find('\0')));
    if (!line.empty()) header.lines.push_back(std::move(line));
    return header;
}

// Whether a header line is the "data file" field the way teem finds fields: the text before the
// line's first ": " names the field, in any case, with or without its space ("datafile"); a
// line holding ":=" is a key/value pair, a line starting with '#' a comment. Spaces, tabs and
// underscores are ignored here, and any ':' ends the name, so that every spelling teem might
// take is checked (one it does not take is only checked in vain).
bool isDataFileField(const std::string& line, std::string& value) {
    if (line.empty() || line[0] == '#' || line.find(":=") != std::string::npos) return false;
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) return false;
    std::string field;
    for (char c : line.substr(0, colon))
        if (c != ' ' && c != '\t' && c != '_') field += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (field != "datafile") return false;
    value = line.substr(colon + 1);
    const auto first = value.find_first_not_of(" \t");  // teem skips the separators after ": "
    value = first == std::string::npos ? std::string() : value.substr(first);
    return true;
}

// The data files the header names ("data file: NAME", "data file: LIST" followed by one name a
// line), each resolved and checked by `named`; none for attached data. A numbered pattern
// ("data file: FORMAT MIN MAX STEP", any '%') is refused: its names are not listed to check;
// so is "-", teem's standard input.
std::vector<std::string> dataFiles(const HeaderText& header, const NamedFiles& named, const std::string& what) {
    std::vector<std::string> files;
    const auto resolve = [&](const std::string& name) {
        if (name == "-") throw Error(ErrorCode::Unsupported, what + ": names standard input ('-') as its data file");
        files.push_back(named.resolve(name));
    };
    for (std::size_t i = 1; i < header.lines.size(); ++i) {
        std::string value;
        if (!isDataFileField(header.lines[i], value)) continue;
        if (value.rfind("LIST", 0) == 0) {  // teem takes any value starting so as a list
            for (std::size_t k = i + 1; k < header.lines.size(); ++k) resolve(header.lines[k]);
            break;
        }
        if (value.find('%') != std::string::npos)
            throw Error(ErrorCode::Unsupported, what + ": a numbered data file pattern is not read; name the files "
                                                       "with 'data file: LIST'");
        resolve(value);
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
