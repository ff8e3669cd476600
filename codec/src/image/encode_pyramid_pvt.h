// The CPU encoder's source pyramid (encode.cpp): box-filtered levels built on first use, from
// floats or straight from 8-bit codes, and the memory of earlier encodes' levels.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "area_downsample_pvt.h"
#include "conus/codec/image/encode.h"
#include "conus/core/image.h"
#include "conus/core/parallel.h"

namespace conus::codec {

// EncodeLevels's fields, for the Pyramid below.
class EncodeLevelsAccess {
public:
    static const float*& source(EncodeLevels& k) { return k.m_source; }
    static int& width(EncodeLevels& k) { return k.m_width; }
    static int& height(EncodeLevels& k) { return k.m_height; }
    static int& channels(EncodeLevels& k) { return k.m_channels; }
    static std::vector<Image>& levels(EncodeLevels& k) { return k.m_levels; }
};

namespace detail {

// Throws InvalidArgument (naming `what`) where `codes` is empty or its codes do not fill it.
void checkCodes(const EightBitImage& codes, const char* what);

// The memory of the last encodes' pyramid levels, kept for the next encode of a source of the
// same size (the budget's confirming encodes and the final one, a batch of photos from one
// camera): a fresh 50 MB level is first touched page by page, and the kernel's clearing of those
// pages cost more than building the level (perf: clear_page ~20 % of a repeated 4096^2 encode).
// Every value of a level is written when it is built, so a kept array is handed out as it is.
// At most kMaxKeptBytes are kept; the oldest arrays go first.
class LevelMemory {
public:
    static constexpr std::size_t kMaxKeptBytes = std::size_t{160} << 20;

    // An array of exactly `values` floats: a kept one if there is one, else a new one (makeImage:
    // huge pages, faulted in on every core).
    static std::vector<float> take(std::size_t values, int width, int height, const std::vector<std::string>& channels) {
        {
            std::lock_guard lock(mutex());
            std::vector<std::vector<float>>& kept = store();
            for (auto it = kept.rbegin(); it != kept.rend(); ++it)
                if (it->size() == values) {
                    std::vector<float> found = std::move(*it);
                    kept.erase(std::next(it).base());
                    return found;
                }
        }
        return std::move(makeImage(width, height, channels).pixels);
    }
    static void give(std::vector<float>&& array) {
        const std::size_t bytes = array.size() * sizeof(float);
        if (bytes == 0 || bytes > kMaxKeptBytes) return;
        std::lock_guard lock(mutex());
        std::vector<std::vector<float>>& kept = store();
        kept.push_back(std::move(array));
        std::size_t total = 0;
        for (const auto& a : kept) total += a.size() * sizeof(float);
        while (total > kMaxKeptBytes) {
            total -= kept.front().size() * sizeof(float);
            kept.erase(kept.begin());
        }
    }

private:
    static std::mutex& mutex() {
        static std::mutex m;
        return m;
    }
    static std::vector<std::vector<float>>& store() {
        static std::vector<std::vector<float>> s;
        return s;
    }
};


// Box-filtered mip levels of the source, each built the first time a footprint needs it (or, for
// a float source, taken from `kept`, where the same source's levels were left by an earlier encode). A source
// of 8-bit codes (EightBitImage) is never made linear as a whole: level 1 is built from its codes
// through the tables (at an exact halving; otherwise from level 0 made linear whole), and level 0,
// an array whose pages are touched only where written, is made linear a band of rows at a time,
// the bands footprints on it read (ensureRows) the first time one does.
class Pyramid {
public:
    static constexpr int kMaxLevels = 40;
    static constexpr int kBandRows = 16;
    using Access = EncodeLevelsAccess;

    Pyramid(const Image& source, EncodeLevels* kept)
        : m_source(&source), m_names(&source.channels), m_channels(source.channelCount()), m_kept(kept) {
        addSizes(source.width, source.height);
        if (!m_kept) return;
        if (Access::source(*m_kept) != source.pixels.data() || Access::width(*m_kept) != source.width ||
            Access::height(*m_kept) != source.height || Access::channels(*m_kept) != m_channels) {
            m_kept->clear();
            Access::source(*m_kept) = source.pixels.data();
            Access::width(*m_kept) = source.width;
            Access::height(*m_kept) = source.height;
            Access::channels(*m_kept) = m_channels;
        }
        std::vector<Image>& held = Access::levels(*m_kept);
        for (int l = 1; l < std::min<int>(levels(), static_cast<int>(held.size())); ++l)
            if (!held[l].pixels.empty()) {
                m_levels[l] = std::move(held[l].pixels);
                std::call_once(m_once[l], [] {});
                m_built[l].store(true, std::memory_order_release);
            }
    }
    explicit Pyramid(const EightBitImage& codes)
        : m_codes(&codes), m_names(&codes.channels), m_channels(codes.channelCount()) {
        addSizes(codes.width, codes.height);
        m_bands = (codes.height + kBandRows - 1) / kBandRows;
        m_bandOnce = std::make_unique<std::once_flag[]>(static_cast<std::size_t>(m_bands));
        m_bandDone = std::make_unique<std::atomic<bool>[]>(static_cast<std::size_t>(m_bands));
        // new float[]: no value written, so no page touched until a band is made linear.
        m_linear.reset(new float[static_cast<std::size_t>(codes.width) * codes.height * m_channels]);
        for (int c = 0; c < m_channels; ++c)
            m_tables.push_back(isColourChannelName(codes.channels[c]) ? srgbCodeToLinear() : codeToUnit());
    }
    // The levels built or taken go back to `kept` when there is one, else their memory to
    // LevelMemory for the next encode.
    ~Pyramid() {
        if (!m_kept) {
            for (std::vector<float>& level : m_levels) LevelMemory::give(std::move(level));
            return;
        }
        std::vector<Image>& held = Access::levels(*m_kept);
        held.resize(levels());
        for (int l = 1; l < levels(); ++l)
            if (!m_levels[l].empty()) held[l] = Image{width(l), height(l), *m_names, std::move(m_levels[l])};
    }
    Pyramid(const Pyramid&) = delete;
    Pyramid& operator=(const Pyramid&) = delete;
    int levels() const { return static_cast<int>(m_sizes.size()); }
    int width(int level) const { return m_sizes[level][0]; }
    int height(int level) const { return m_sizes[level][1]; }
    // The first worker to need a level builds it with all threads while the others wait for it.
    // Level 0 of 8-bit codes holds only the bands made linear so far: see ensureRows. Every pixel
    // asks for its levels, so a built one is found by one atomic load: std::call_once sets
    // thread-local state and calls pthread_once on every call.
    Plane level(int level, int threads) {
        if (level == 0) return {m_codes ? m_linear.get() : m_source->pixels.data(), width(0), height(0)};
        if (m_built[level].load(std::memory_order_acquire)) return {m_levels[level].data(), width(level), height(level)};
        std::call_once(m_once[level], [&] {
            const std::size_t values = static_cast<std::size_t>(width(level)) * height(level) * m_channels;
            std::vector<float> built = LevelMemory::take(values, width(level), height(level), *m_names);
            if (level == 1 && m_codes && width(1) * 2 == width(0) && height(1) * 2 == height(0)) {
                halveCodes(built.data(), threads);
            } else {
                if (level == 1) ensureRows(0, 0.0, height(0));
                const Plane below = this->level(level - 1, threads);
                areaDownsamplePlane(below, built.data(), width(level), height(level), m_channels, threads);
            }
            m_levels[level] = std::move(built);  // only a whole level is ever kept
            m_built[level].store(true, std::memory_order_release);
        });
        return {m_levels[level].data(), width(level), height(level)};
    }
    // Before level `level` is read between rows y0 and y1 (texel coordinates): the bands of level
    // 0 of 8-bit codes that hold them, and the rows a bilinear tap and a four-float read reach
    // beyond, made linear. Nothing to do on a float source or another level.
    void ensureRows(int level, double y0, double y1) {
        if (level != 0 || !m_codes) return;
        const int last = height(0) - 1;
        const int first = std::clamp(static_cast<int>(std::floor(y0)) - 1, 0, last);
        const int end = std::clamp(static_cast<int>(std::ceil(y1)) + 2, 0, last);
        for (int b = first / kBandRows; b <= end / kBandRows; ++b)
            if (!m_bandDone[b].load(std::memory_order_acquire))
                std::call_once(m_bandOnce[b], [&] {
                    linearBand(b);
                    m_bandDone[b].store(true, std::memory_order_release);
                });
    }

private:
    void addSizes(int w, int h) {
        m_sizes.push_back({w, h});
        while ((w > 1 || h > 1) && static_cast<int>(m_sizes.size()) < kMaxLevels) {
            w = std::max(1, (w + 1) / 2);
            h = std::max(1, (h + 1) / 2);
            m_sizes.push_back({w, h});
        }
    }
    void linearBand(int band) {
        const std::size_t begin = static_cast<std::size_t>(band) * kBandRows * width(0) * m_channels;
        const std::size_t end = std::min<std::size_t>(begin + std::size_t(kBandRows) * width(0) * m_channels,
                                                      std::size_t(width(0)) * height(0) * m_channels);
        const std::uint8_t* codes = m_codes->codes.data();
        float* out = m_linear.get();
        for (std::size_t i = begin; i < end; i += m_channels)
            for (int c = 0; c < m_channels; ++c) out[i + c] = m_tables[c][codes[i + c]];
    }
    // Level 1 at an exact halving: each texel the mean of its 2x2 source pixels, made linear.
    void halveCodes(float* out, int threads) {
        const int w = width(1), sw = width(0), ch = m_channels;
        const std::uint8_t* codes = m_codes->codes.data();
        parallelRows(height(1), threads, [&](int y0, int y1) {
            for (int y = y0; y < y1; ++y) {
                const std::uint8_t* r0 = codes + std::size_t(2 * y) * sw * ch;
                const std::uint8_t* r1 = r0 + std::size_t(sw) * ch;
                float* o = out + std::size_t(y) * w * ch;
                for (int x = 0; x < w; ++x)
                    for (int c = 0; c < ch; ++c) {
                        const float* t = m_tables[c];
                        const std::size_t i = std::size_t(2 * x) * ch + c;
                        o[std::size_t(x) * ch + c] = 0.25f * ((t[r0[i]] + t[r0[i + ch]]) + (t[r1[i]] + t[r1[i + ch]]));
                    }
            }
        });
    }

    const Image* m_source = nullptr;
    const EightBitImage* m_codes = nullptr;
    const std::vector<std::string>* m_names = nullptr;
    int m_channels;
    EncodeLevels* m_kept = nullptr;  // a float source's levels kept across encodes (EncodeOptions::keptLevels)
    std::vector<std::array<int, 2>> m_sizes;
    std::array<std::vector<float>, kMaxLevels> m_levels;
    std::array<std::once_flag, kMaxLevels> m_once;
    std::array<std::atomic<bool>, kMaxLevels> m_built{};  // set once a level's m_once has run
    // 8-bit codes: level 0's array, its bands' flags, and each channel's table.
    std::unique_ptr<float[]> m_linear;
    std::unique_ptr<std::once_flag[]> m_bandOnce;
    std::unique_ptr<std::atomic<bool>[]> m_bandDone;
    int m_bands = 0;
    std::vector<const float*> m_tables;
};

}  // namespace detail
}  // namespace conus::codec
