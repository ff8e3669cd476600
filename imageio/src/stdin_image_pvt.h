// Private to the OpenImageIO module: a picture read from standard input, whole and bounded by
// what its header declares, with a name whose extension tells OpenImageIO the format.
#pragma once

#include <string>
#include <vector>

namespace conus::imageio::oiio {

// Standard input, read whole (bounded), with a name whose extension tells OpenImageIO the format.
struct StdinImage {
    std::vector<unsigned char> bytes;
    std::string name;
};

// The extension OpenImageIO knows the format by, from the first bytes; empty for none CoNUS reads.
const char* stdinExtension(const std::vector<unsigned char>& bytes);

// Standard input read to its end: refused (conus::Error) when it is no picture CoNUS reads, empty,
// or longer than its header's picture can take (448 MiB where the header does not say).
StdinImage readStdin();

}  // namespace conus::imageio::oiio
