// Private to format/: OpenEXR headers <-> HeaderModel (exr_header.cpp). kAttributes' rows are read
// and written here with no code per attribute; a part's header is built from its PartModel.
#pragma once

#include <ImfHeader.h>
#include <ImfMultiPartInputFile.h>

#include "conus/format/container.h"
#include "header_model_pvt.h"

namespace conus::format::detail {

// The parts of `file` and every attribute of the parts kParts names, each name followed by
// `suffix` (HeaderModel::partName).
HeaderModel modelOf(const Imf::MultiPartInputFile& file, const std::string& suffix = "");

// The header of one part as the writer writes it (its attributes come separately).
Imf::Header exrHeader(const PartModel& p);

// Every attribute of `part` the model holds, into its header `h`.
void writeAttributes(const HeaderModel& m, PartKind part, Imf::Header& h);

// A read model's attributes as a ConusFile's fields, and the source metadata `h` (the `conus`
// part's header) carries.
void fillMetadata(const HeaderModel& m, const Imf::Header& h, ConusFile& out);

}  // namespace conus::format::detail
