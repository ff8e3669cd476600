// The plain float image: channel lookup and checked allocation.
#include <algorithm>
#include <cstdint>
#include <string>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "conus/core/error.h"
#include "conus/core/image.h"
#include "conus/core/parallel.h"

namespace conus {

int Image::channelIndex(const std::string& name) const {
    for (std::size_t c = 0; c < channels.size(); ++c) {
        if (channels[c] == name) return static_cast<int>(c);
    }
    return -1;
}

namespace {

// Large pixel arrays are first touched in 2 MiB pages where the kernel leaves that to the program
// (transparent huge pages in "madvise" mode): a 4096^2 RGB float image is 48k page faults in 4 KiB
// pages, which took 0.6 s of a `conus encode` in a virtual machine (bench/notes/2026-11-24-end-to-end.md),
// and 96 in huge pages. Only the whole 2 MiB pages inside the array are advised; a hint, not a
// requirement, so failure changes nothing.
void adviseHugePages([[maybe_unused]] void* data, [[maybe_unused]] std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
    if (bytes < 4 * kHuge) return;
    const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
    const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kHuge - 1);
    if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
}

// A large array's pages are faulted in by every core at once: the kernel clears each page when it
// is first touched, and in a virtual machine that clearing (and the host's own fault behind it)
// can cost more than the work that fills the image (`perf`: 23% of a 4096^2 `conus encode`'s CPU
// in clear_page under makeImage, on one thread). MADV_POPULATE_WRITE (Linux 5.14) faults a range
// in without writing to it, 2 MiB (a huge page) a chunk; where it is missing, the caller's own
// writes fault the pages in as before.
void populateInParallel([[maybe_unused]] void* data, [[maybe_unused]] std::size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    constexpr std::uintptr_t kChunk = std::uintptr_t{2} << 20;
    constexpr std::size_t kAtLeast = std::size_t{32} << 20;
    if (bytes < kAtLeast) return;
    // Whole pages inside the array only (madvise takes page-aligned ranges).
    const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + 4095) & ~std::uintptr_t{4095};
    const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~std::uintptr_t{4095};
    const int chunks = static_cast<int>((end - begin + kChunk - 1) / kChunk);
    parallelRows(chunks, 0, [&](int c0, int c1) {
        const std::uintptr_t from = begin + c0 * kChunk, to = std::min(end, begin + c1 * kChunk);
        ::madvise(reinterpret_cast<void*>(from), to - from, MADV_POPULATE_WRITE);  // a hint: failure changes nothing
    });
#endif
}

}  // namespace

Image makeImage(int width, int height, std::vector<std::string> channels) {
    if (width < 1 || height < 1 || channels.empty()) {
        throw Error(ErrorCode::InvalidArgument,
                    "makeImage: need width, height and channel count >= 1, got " + std::to_string(width) +
                        "x" + std::to_string(height) + " with " + std::to_string(channels.size()) +
                        " channels");
    }
    // Sizes in 64-bit before allocating, so absurd requests fail cleanly instead of overflowing.
    const std::int64_t pixels = std::int64_t{width} * height;
    if (width > kMaxImageSide || height > kMaxImageSide || pixels > kMaxImagePixels) {
        throw Error(ErrorCode::LimitExceeded, "makeImage: " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " exceeds the limit of " +
                                                  std::to_string(kMaxImageSide) + " a side, " +
                                                  std::to_string(kMaxImagePixels) + " pixels");
    }
    Image image;
    image.width = width;
    image.height = height;
    image.channels = std::move(channels);
    const std::size_t values = static_cast<std::size_t>(pixels) * image.channels.size();
    image.pixels.reserve(values);
    adviseHugePages(image.pixels.data(), values * sizeof(float));
    populateInParallel(image.pixels.data(), values * sizeof(float));
    image.pixels.assign(values, 0.0f);
    return image;
}

void checkImage(const Image& image, const char* what) {
    if (image.empty())
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": empty image (" + std::to_string(image.width) +
                                                    "x" + std::to_string(image.height) + ", " +
                                                    std::to_string(image.channelCount()) + " channels)");
    const std::size_t expected = static_cast<std::size_t>(image.width) * image.height * image.channels.size();
    if (image.pixels.size() != expected)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": image holds " +
                                                    std::to_string(image.pixels.size()) + " values, expected " +
                                                    std::to_string(expected));
}

std::vector<std::string> displayOrder(const std::vector<std::string>& channels) {
    std::vector<std::string> out;
    for (const char* name : {"R", "G", "B", "Y", "A", "Z"})
        if (std::find(channels.begin(), channels.end(), name) != channels.end()) out.push_back(name);
    for (const std::string& c : channels)
        if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
    return out;
}

}  // namespace conus
