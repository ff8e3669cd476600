// Fuzz harness: the container reader and validator on arbitrary bytes, then, for a file that
// reads, the sampling map it holds (inverse included) and a small decode. The bytes become a
// memfd, a regular file in memory, because the reader takes paths; no disk, thousands of runs a
// second.
#include <sys/mman.h>
#include <unistd.h>

#include <string>

#include "conus/codec/image/decode.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "fuzz.h"

namespace {

using namespace conus;

class MemoryFile {
public:
    MemoryFile() : m_fd(::memfd_create("conus-fuzz", MFD_CLOEXEC)) {
        CONUS_FUZZ_CHECK(m_fd >= 0, "memfd_create");
        m_path = "/proc/self/fd/" + std::to_string(m_fd);
    }
    void assign(const std::uint8_t* data, std::size_t size) {
        CONUS_FUZZ_CHECK(::ftruncate(m_fd, 0) == 0, "ftruncate");
        std::size_t done = 0;
        while (done < size) {
            const ssize_t n = ::pwrite(m_fd, data + done, size - done, static_cast<off_t>(done));
            CONUS_FUZZ_CHECK(n > 0, "pwrite");
            done += static_cast<std::size_t>(n);
        }
    }
    const std::string& path() const { return m_path; }

private:
    int m_fd;
    std::string m_path;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static MemoryFile file;
    file.assign(data, size);
    // Small enough that every run stays fast; the reader's checks are the same at any limit. An
    // input of scripts/fuzz.sh's 16 KB holds no legitimate image past these (ZIP's best is about
    // 1,000:1), so larger declared sizes are refused from the header, as the tools refuse theirs.
    conus::Limits limits;
    limits.maxPixels = std::int64_t{1} << 18;
    limits.maxDecodeBytes = std::int64_t{8} << 20;

    format::ValidationReport report;
    try {
        report = format::validateConusFile(file.path(), limits);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "validateConusFile threw: %s\n", e.what());
        CONUS_FUZZ_CHECK(false, "validateConusFile never throws for bad content");
    }
    CONUS_FUZZ_CHECK(isOneLine(report.str()), "a report is one line");

    return readOrRefuse([&] {
        const format::ConusFile conusFile = format::readConusFile(file.path(), limits);
        CONUS_FUZZ_CHECK(report.ok(), "readConusFile accepted a file validateConusFile refused");
        const codec::SamplingMap map = codec::SamplingMap::fromGrid(conusFile.map);
        for (const glm::dvec2 p : {glm::dvec2(0.5, 0.5), glm::dvec2(0.1, 0.9), glm::dvec2(1.0, 0.0)}) {
            const glm::dvec2 back = map.distort(map.undistort(p));
            CONUS_FUZZ_CHECK(std::abs(back.x - p.x) < 1e-7 && std::abs(back.y - p.y) < 1e-7, "distort(undistort(p)) == p");
        }
        codec::DecodeOptions decode;
        decode.width = 8;
        decode.height = 6;
        decode.threads = 1;
        const Image frame = codec::decodeImage(conusFile.image, map, decode);
        CONUS_FUZZ_CHECK(frame.width == 8 && frame.height == 6, "decode size");
    });
}
