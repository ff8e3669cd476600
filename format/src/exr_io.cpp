// Reading and writing a CoNUS file through OpenEXR: the screen before OpenEXR's C++ library reads
// (exr_screen.h), the header rules on the model of the headers (exr_header.h), then the parts'
// pixels (exr_parts.h). OpenEXR's exceptions (Iex::BaseExc derives from std::exception) are caught
// here and turned into report issues or conus::Error, so nothing from OpenEXR escapes format/.
#include "exr_io.h"

#include <ImfHeader.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfStringAttribute.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>
#include <variant>

#include "exr_header.h"
#include "exr_parts.h"
#include "exr_screen.h"
#include "header_model.h"

namespace conus::format::detail {

LoadResult loadConusFile(const std::string& path, const Limits& limits, bool readPixels, ConusFile& out) {
    useExrThreads();
    LoadResult result;
    ValidationReport& r = result.report;
    auto refuse = [&](const Problem& problem) {
        r.add(problem.rule, problem.message);
        result.code = problem.code;
        return result;
    };
    // A FIFO never ends and a device may not either: only regular files are read.
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
        return refuse({Rule::V1, ErrorCode::Io, "cannot open " + path + ": " + (ec ? ec.message() : std::string("no such file"))});
    }
    if (!std::filesystem::is_regular_file(status)) return refuse({Rule::V1, ErrorCode::Io, "cannot read " + path + ": not a regular file"});
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec || !std::ifstream(path, std::ios::binary)) {
        return refuse({Rule::V1, ErrorCode::Io, "cannot open " + path + (ec ? ": " + ec.message() : std::string())});
    }
    std::unique_ptr<CoreFile> opened;
    if (Problem problem = checkHeaders(path, size, limits, opened); !problem.message.empty()) return refuse(problem);
    const CoreFile& core = *opened;
    try {
        Imf::MultiPartInputFile file(path.c_str());
        const HeaderModel model = modelOf(file);
        const HeaderCheck hc = checkHeaderRules(model, limits, r);
        if (!r.ok()) {
            result.code = hc.notConus ? ErrorCode::NotConus : hc.limitExceeded ? ErrorCode::LimitExceeded : ErrorCode::Corrupt;
            return result;
        }
        // Headers passed every rule, so every size below is within limits; the chunk tables must
        // still show that the pixels are in the file before memory is committed for them.
        const PartModel& part = model.part(PartKind::Conus);
        if (readPixels) {
            const std::int64_t bytes = part.dataWindow.width() * part.dataWindow.height() *
                                       std::int64_t(part.channels.size()) * std::int64_t(sizeof(float));
            if (bytes > limits.maxDecodeBytes) {
                return refuse({Rule::V4, ErrorCode::LimitExceeded,
                               "image of " + std::to_string(part.dataWindow.width()) + "x" + std::to_string(part.dataWindow.height()) +
                                   "x" + std::to_string(part.channels.size()) + " floats takes " + std::to_string(bytes) +
                                   " bytes, beyond the decode memory limit of " + std::to_string(limits.maxDecodeBytes)});
            }
        }
        for (const PartSpec& spec : kParts) {
            const int p = model.slot(spec.kind).index;
            if (Problem problem = checkChunks(core.ctx(), p, size); !problem.message.empty()) return refuse(problem);
        }
        ConusFile loaded;
        fillMetadata(model, file.header(model.slot(PartKind::Conus).index), loaded);
        if (readPixels) {
            readImagePart(file, model.slot(PartKind::Conus).index, part, loaded.image);
        } else {
            loaded.image.width = int(part.dataWindow.width());
            loaded.image.height = int(part.dataWindow.height());
            for (const ChannelModel& c : part.channels) loaded.image.channels.push_back(c.name);
        }
        readMapPart(file, model.slot(PartKind::SamplingMap).index, model.part(PartKind::SamplingMap), loaded.map);
        const ValidationReport grid = validateGrid(loaded.map);
        r.issues.insert(r.issues.end(), grid.issues.begin(), grid.issues.end());
        if (!r.ok()) {
            result.code = ErrorCode::InvalidMap;
            return result;
        }
        out = std::move(loaded);
    } catch (const std::exception& e) {
        r.add(Rule::V1, std::string("damaged OpenEXR data: ") + e.what());
        result.code = ErrorCode::Corrupt;
    }
    return result;
}

void writeExrFile(AtomicFile& out, const ConusFile& file) {
    useExrThreads();
    const Image& im = file.image;
    const std::string& path = out.destination();
    AtomicOStream stream(out);
    try {
        // The parts and attributes the validator checked (header_model.cpp), then the source's
        // metadata, which only the `conus` part carries.
        const HeaderModel model = modelOf(file);
        std::vector<Imf::Header> headers;
        for (const PartModel& part : model.parts) headers.push_back(exrHeader(part));
        for (const PartSpec& spec : kParts) writeAttributes(model, spec.kind, headers[model.slot(spec.kind).index]);
        Imf::Header& conus = headers[model.slot(PartKind::Conus).index];
        for (const MetadataItem& item : file.sourceEncoding.metadata) {
            if (!isCarriedMetadata(item.name)) continue;  // never let an item overwrite a CoNUS attribute
            if (const auto* v = std::get_if<std::string>(&item.value)) conus.insert(item.name, Imf::StringAttribute(*v));
            else if (const auto* i = std::get_if<int>(&item.value)) conus.insert(item.name, Imf::IntAttribute(*i));
            else if (const auto* f = std::get_if<float>(&item.value)) conus.insert(item.name, Imf::FloatAttribute(*f));
            else if (const auto* d = std::get_if<double>(&item.value)) conus.insert(item.name, Imf::DoubleAttribute(*d));
        }
        Imf::MultiPartOutputFile exr(stream, headers.data(), int(headers.size()));
        writeImagePart(exr, model.slot(PartKind::Conus).index, im, file.pixelType);
        writeMapPart(exr, model.slot(PartKind::SamplingMap).index, file.map);
    } catch (const std::exception& e) {
        throw Error(ErrorCode::Io, stream.failure().empty() ? "cannot write " + path + ": " + e.what() : stream.failure());
    }
    if (!stream.failure().empty()) throw Error(ErrorCode::Io, stream.failure());
}

}  // namespace conus::format::detail
