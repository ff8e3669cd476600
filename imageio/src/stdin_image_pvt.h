// Private to the OpenImageIO module: a picture read from standard input, whole and bounded by
// what its header declares, with a name whose extension tells OpenImageIO the format.
#pragma once

#include <cstddef>
#include <span>
#include <string>

namespace conus::imageio::oiio {

// The bytes of standard input, in one anonymous mapping of the most a stream may hold: pages are
// committed only as bytes arrive, and the bytes never move, so holding N bytes costs N (a growing
// array's copies cost up to twice that).
class StdinBytes {
public:
    StdinBytes() = default;
    StdinBytes(StdinBytes&& other) noexcept;
    StdinBytes& operator=(StdinBytes&& other) noexcept;
    ~StdinBytes();

    const unsigned char* data() const { return m_base; }
    std::size_t size() const { return m_size; }
    std::span<const unsigned char> view() const { return {m_base, m_size}; }

    // Reserves `capacity` bytes of address space (none of memory); throws conus::Error when the
    // system refuses it. Appends never pass it.
    explicit StdinBytes(std::size_t capacity);
    void append(const unsigned char* bytes, std::size_t count);

private:
    unsigned char* m_base = nullptr;
    std::size_t m_capacity = 0, m_size = 0;
};

// Standard input, read whole (bounded), with a name whose extension tells OpenImageIO the format.
struct StdinImage {
    StdinBytes bytes;
    std::string name;
};

// The extension OpenImageIO knows the format by, from the first bytes; empty for none CoNUS reads.
const char* stdinExtension(std::span<const unsigned char> bytes);

// Standard input read to its end: refused (conus::Error) when it is no picture CoNUS reads, empty,
// or longer than its header's picture can take (256 MiB where the header does not say).
StdinImage readStdin();

}  // namespace conus::imageio::oiio
