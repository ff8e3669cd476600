// The mipmapped GL encoder's transfers (gpu_upload.h).
#include "gpu_upload_pvt.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "conus/core/error.h"
#include "conus/core/parallel.h"

namespace conus::renderers {
namespace {

// Float bits >> kBucketShift index the table of 8-bit sRGB codes: a bucket spans 2^-9 of its value,
// less than the smallest relative gap between two codes' rounding thresholds (0.87%, at the top),
// so the bucket's code is right or one short.
constexpr int kBucketShift = 14;
constexpr std::uint32_t kOneBits = 0x3F800000u;  // 1.0f

struct Srgb8Tables {
    std::array<float, 256> linear{};      // each code's linear value
    std::array<float, 256> threshold{};   // the linear value halfway between codes c and c + 1 (in sRGB)
    std::vector<std::uint8_t> bucketCode;  // the code of each bucket's lowest value

    Srgb8Tables() {
        const auto toLinear = [](double s) { return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4); };
        for (int c = 0; c < 256; ++c) {
            linear[c] = static_cast<float>(toLinear(c / 255.0));
            threshold[c] = c < 255 ? static_cast<float>(toLinear((c + 0.5) / 255.0)) : 2.0f;
        }
        bucketCode.resize((kOneBits >> kBucketShift) + 1);
        int code = 0;
        for (std::uint32_t k = 0; k < bucketCode.size(); ++k) {
            const std::uint32_t bits = k << kBucketShift;
            float value;
            std::memcpy(&value, &bits, sizeof value);
            while (code < 255 && value > threshold[code]) ++code;
            bucketCode[k] = static_cast<std::uint8_t>(code);
        }
    }

    // The nearest code (in sRGB) to linear v, clamped to [0, 1].
    std::uint8_t code(float v) const {
        if (!(v > 0.0f)) return 0;
        if (v >= 1.0f) return 255;
        std::uint32_t bits;
        std::memcpy(&bits, &v, sizeof bits);
        int c = bucketCode[bits >> kBucketShift];
        if (c < 255 && v > threshold[c]) ++c;
        return static_cast<std::uint8_t>(c);
    }
};

const Srgb8Tables& srgb8Tables() {
    static const Srgb8Tables tables;
    return tables;
}

// A value read from an 8-bit file and linearised (by the PNG reader's table, or OpenColorIO in
// float) is its code's value to a few float roundings; 1e-4 of it is still 40 times closer than the
// next code (0.4% apart at the top) and under half a half float's step.
bool near(float value, float exact) { return std::abs(value - exact) <= 1e-4f * exact + 1e-9f; }

// Float to half by table (round toward zero; finite values above 65504 become infinity), after
// "Fast Half Float Conversions" (J. van der Zijp, 2008).
struct HalfTables {
    std::array<std::uint16_t, 512> base{};
    std::array<std::uint8_t, 512> shift{};
    HalfTables() {
        for (int i = 0; i < 256; ++i) {
            const int e = i - 127;
            std::uint16_t b;
            std::uint8_t s;
            if (e < -24) b = 0, s = 24;
            else if (e < -14) b = static_cast<std::uint16_t>(0x0400 >> (-e - 14)), s = static_cast<std::uint8_t>(-e - 1);
            else if (e <= 15) b = static_cast<std::uint16_t>((e + 15) << 10), s = 13;
            else if (e < 128) b = 0x7C00, s = 24;
            else b = 0x7C00, s = 13;
            base[i] = b;
            base[i | 0x100] = static_cast<std::uint16_t>(b | 0x8000);
            shift[i] = shift[i | 0x100] = s;
        }
    }
    std::uint16_t half(float v) const {
        std::uint32_t f;
        std::memcpy(&f, &v, sizeof f);
        const std::uint32_t k = (f >> 23) & 0x1FF;
        return static_cast<std::uint16_t>(base[k] + ((f & 0x007FFFFF) >> shift[k]));
    }
};

const HalfTables& halfTables() {
    static const HalfTables tables;
    return tables;
}

bool isColourPass(const Image& image, int first, int count) {
    static const char* const kNames[] = {"R", "G", "B", "A"};
    if (count < 3) return false;
    for (int c = 0; c < count; ++c)
        if (image.channels[first + c] != kNames[c]) return false;
    return true;
}

// Rows [y0, y1) of an R, G, B (, A) pass into RGBA 8-bit sRGB texels; when `exactOnly`, stops (and
// sets `stop`) at the first row holding a value that is not exactly a code's.
void toSrgb8(const Image& image, int first, int count, int y0, int y1, std::uint8_t* texels, bool exactOnly,
             std::atomic<bool>& stop) {
    const Srgb8Tables& t = srgb8Tables();
    const int channels = image.channelCount();
    for (int y = y0; y < y1; ++y) {
        if (exactOnly && stop.load(std::memory_order_relaxed)) return;
        const float* from = image.pixels.data() + (static_cast<std::size_t>(y) * image.width) * channels + first;
        std::uint8_t* to = texels + static_cast<std::size_t>(y) * image.width * 4;
        bool exact = true;
        for (int x = 0; x < image.width; ++x, from += channels, to += 4) {
            for (int c = 0; c < 3; ++c) {
                const std::uint8_t code = t.code(from[c]);
                exact &= near(from[c], t.linear[code]);
                to[c] = code;
            }
            if (count == 4) {
                const float a = std::clamp(from[3], 0.0f, 1.0f) * 255.0f;
                const auto code = static_cast<std::uint8_t>(a + 0.5f);
                exact &= near(from[3], code / 255.0f);
                to[3] = code;
            } else {
                to[3] = 255;
            }
        }
        if (exactOnly && !exact) {
            stop.store(true, std::memory_order_relaxed);
            return;
        }
    }
}

void toHalf(const Image& image, int first, int count, int y0, int y1, std::uint16_t* texels) {
    const HalfTables& t = halfTables();
    const int channels = image.channelCount();
    const bool colour = count == 3 && isColourPass(image, first, count);
    for (int y = y0; y < y1; ++y) {
        const float* from = image.pixels.data() + (static_cast<std::size_t>(y) * image.width) * channels + first;
        std::uint16_t* to = texels + static_cast<std::size_t>(y) * image.width * 4;
        for (int x = 0; x < image.width; ++x, from += channels, to += 4) {
            for (int c = 0; c < 4; ++c) to[c] = c < count ? t.half(from[c]) : 0;
            if (colour) to[3] = 0x3C00;  // 1.0
        }
    }
}

// Unbinds a pixel buffer object on the way out, so that no later client-memory transfer of this
// context reads or writes into it.
class BoundBuffer {
public:
    BoundBuffer(const GladGLContext& gl, GLenum target) : m_gl(gl), m_target(target), m_buffer(makeBufferId(gl)) {
        gl.BindBuffer(target, m_buffer);
    }
    ~BoundBuffer() {
        if (m_mapped) m_gl.UnmapBuffer(m_target);
        m_gl.BindBuffer(m_target, 0);
        m_gl.DeleteBuffers(1, &m_buffer);
    }
    BoundBuffer(const BoundBuffer&) = delete;
    BoundBuffer& operator=(const BoundBuffer&) = delete;

    // (Re)allocates `bytes` and maps them.
    void* map(std::size_t bytes, GLenum usage, GLbitfield access) {
        unmap();
        m_gl.BufferData(m_target, static_cast<GLsizeiptr>(bytes), nullptr, usage);
        void* data = m_gl.MapBufferRange(m_target, 0, static_cast<GLsizeiptr>(bytes), access);
        if (!data) throw Error(ErrorCode::LimitExceeded, "encodeImageGpu: the GL driver could not map a pixel buffer of " +
                                                             std::to_string(bytes) + " bytes");
        m_mapped = true;
        return data;
    }
    void unmap() {
        if (m_mapped) m_gl.UnmapBuffer(m_target);
        m_mapped = false;
    }

private:
    static GLuint makeBufferId(const GladGLContext& gl) {
        GLuint id = 0;
        gl.GenBuffers(1, &id);
        return id;
    }
    const GladGLContext& m_gl;
    GLenum m_target;
    GLuint m_buffer;
    bool m_mapped = false;
};

}  // namespace

GpuUpload uploadPass(const GladGLContext& gl, const Image& image, int first, int count, GpuUpload upload, int levels,
                     int threads) {
    const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
    BoundBuffer buffer(gl, GL_PIXEL_UNPACK_BUFFER);
    GpuUpload used = GpuUpload::Half;
    if (upload != GpuUpload::Half && isColourPass(image, first, count)) {
        auto* texels = static_cast<std::uint8_t*>(buffer.map(pixels * 4, GL_STREAM_DRAW, GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT));
        std::atomic<bool> stop{false};
        const bool exactOnly = upload == GpuUpload::Auto;
        parallelRows(image.height, threads, [&](int y0, int y1) { toSrgb8(image, first, count, y0, y1, texels, exactOnly, stop); }, 16);
        if (!stop.load()) used = GpuUpload::Srgb8;
    }
    if (used == GpuUpload::Half) {
        auto* texels = static_cast<std::uint16_t*>(buffer.map(pixels * 8, GL_STREAM_DRAW, GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT));
        parallelRows(image.height, threads, [&](int y0, int y1) { toHalf(image, first, count, y0, y1, texels); }, 16);
    }
    buffer.unmap();
    const bool srgb = used == GpuUpload::Srgb8;
    gl.TexStorage2D(GL_TEXTURE_2D, levels, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA16F, image.width, image.height);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.width, image.height, GL_RGBA, srgb ? GL_UNSIGNED_BYTE : GL_HALF_FLOAT,
                     nullptr);
    return used;
}

void readBackPass(const GladGLContext& gl, Image& out, int first, int count, int threads) {
    const std::size_t pixels = static_cast<std::size_t>(out.width) * out.height;
    BoundBuffer buffer(gl, GL_PIXEL_PACK_BUFFER);
    gl.BufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(pixels * 4 * sizeof(float)), nullptr, GL_STREAM_READ);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadPixels(0, 0, out.width, out.height, GL_RGBA, GL_FLOAT, nullptr);
    const void* mapped = gl.MapBufferRange(GL_PIXEL_PACK_BUFFER, 0, static_cast<GLsizeiptr>(pixels * 4 * sizeof(float)), GL_MAP_READ_BIT);
    if (!mapped) throw Error(ErrorCode::Unsupported, "encodeImageGpu: the GL driver could not map the read-back buffer");
    const auto* from = static_cast<const float*>(mapped);
    const int channels = out.channelCount();
    parallelRows(out.height, threads, [&](int y0, int y1) {
        for (std::size_t i = static_cast<std::size_t>(y0) * out.width; i < static_cast<std::size_t>(y1) * out.width; ++i)
            for (int c = 0; c < count; ++c) out.pixels[i * channels + first + c] = from[i * 4 + c];
    }, 16);
    gl.UnmapBuffer(GL_PIXEL_PACK_BUFFER);
}

}  // namespace conus::renderers
