// GPU image encode (paper section 3.2) and decode (section 4) on a Context.
//
// Images travel to and from GL in memory order, top row first, so texture row 0 and window row 0
// are the image's top row: GL's y axis is the spec's v (downward) and no flip is needed anywhere;
// the only place one would appear, NDC, is written y = 2v - 1 (encode.vert.glsl).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "context_pvt.h"
#include "conus/renderers/gpu_image.h"
#include "embedded_shaders.h"
#include "gl_objects.h"

namespace conus::gl {
namespace {

constexpr int kChannelsPerPass = 4;


std::string limitDescription(const Context& context, int limit) {
    std::string text = "the texture limit " + std::to_string(limit) + " (GL_MAX_TEXTURE_SIZE " +
                       std::to_string(context.maxTextureSize()) + " of " + context.renderer();
    if (limit < context.maxTextureSize()) text += std::string(", lowered by ") + kTextureLimitVariable;
    return text + ")";
}

void checkTextureSize(const Context& context, int width, int height, const char* what, const char* role) {
    const int limit = context.textureLimit();
    if (width > limit || height > limit)
        throw Error(ErrorCode::LimitExceeded, std::string(what) + ": " + role + " " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " exceeds " +
                                                  limitDescription(context, limit) + "; only the encoder's source is "
                                                  "tiled: use the CPU path");
}

GLenum internalFormat(int channels) {
    static constexpr GLenum kFormats[] = {GL_R32F, GL_RG32F, GL_RGB32F, GL_RGBA32F};
    return kFormats[channels - 1];
}
GLenum pixelFormat(int channels) {
    static constexpr GLenum kFormats[] = {GL_RED, GL_RG, GL_RGB, GL_RGBA};
    return kFormats[channels - 1];
}

// Channels [first, first + count) of an image, interleaved; the image's own array when it is all.
// Uploads keep the image's channel count (R32F .. RGBA32F): measured on llvmpipe, padding RGB to
// RGBA on the CPU made the upload slower, not faster.
class PassPixels {
public:
    PassPixels(const Image& image, int first, int count) {
        const int channels = image.channelCount();
        if (first == 0 && count == channels) {
            m_data = image.pixels.data();
            return;
        }
        const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
        m_copy.resize(pixels * count);
        for (std::size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < count; ++c) m_copy[i * count + c] = image.pixels[i * channels + first + c];
        m_data = m_copy.data();
    }
    const float* data() const { return m_data; }

private:
    std::vector<float> m_copy;
    const float* m_data = nullptr;
};

// Reads the bound framebuffer's first `count` channels into channels [first, first + count).
void readBack(const GladGLContext& gl, Image& out, int first, int count) {
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    const int channels = out.channelCount();
    if (first == 0 && count == channels) {
        gl.ReadPixels(0, 0, out.width, out.height, pixelFormat(count), GL_FLOAT, out.pixels.data());
        return;
    }
    const std::size_t pixels = static_cast<std::size_t>(out.width) * out.height;
    std::vector<float> buffer(pixels * count);
    gl.ReadPixels(0, 0, out.width, out.height, pixelFormat(count), GL_FLOAT, buffer.data());
    for (std::size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < count; ++c) out.pixels[i * channels + first + c] = buffer[i * count + c];
}


// Positions along one axis of the map at which the mesh has vertices: every node, plus `splits[i]`
// equal steps across cell column (or row) i. One count per whole column or row of cells keeps
// neighbouring cells' vertices shared, so the mesh has no cracks.
std::vector<double> meshAxis(const std::vector<int>& splits) {
    const int cells = static_cast<int>(splits.size());
    std::vector<double> out;
    for (int i = 0; i < cells; ++i)
        for (int k = 0; k < splits[i]; ++k) out.push_back((i + static_cast<double>(k) / splits[i]) / cells);
    out.push_back(1.0);
    return out;
}

constexpr int kVertexFloats = 8;

struct Mesh {
    // Per vertex: distorted x, y; undistorted u, v; the footprint (codec::FootprintField), as the
    // undistorted change per CoNUS pixel along x and along y.
    std::vector<float> vertices;
    std::vector<GLuint> indices;
};

// Each map cell is split into sub-quads so the piecewise-linear mesh follows the bilinear cell:
// a cell of twist t = N00 - N10 - N01 + N11 (in CoNUS pixels) split s ways departs from its
// bilinear patch by at most |t| / (4 s^2), kept under kMaxBendPixels; and no sub-quad is longer
// than kMaxSubQuadPixels, so the per-triangle derivatives that size the filter follow the local
// Jacobian. Finer meshes cost llvmpipe dearly (tiny triangles shade whole 2x2 quads).
Mesh buildMesh(const codec::SamplingMap& map, int width, int height) {
    constexpr double kMaxBendPixels = 0.05;
    constexpr double kMaxSubQuadPixels = 8.0;
    // Bounds the mesh (memory and vertex work) for extreme maps; finer subdivision stops here.
    constexpr double kMaxMeshVertices = 4.0e6;
    const int n = map.columns(), m = map.rows();
    const auto pixels = [&](glm::vec2 d) { return std::hypot(double(d.x) * width, double(d.y) * height); };
    // Most splits per cell that keep the whole mesh under kMaxMeshVertices.
    const int maxSplits = static_cast<int>(std::max(1.0, std::sqrt(kMaxMeshVertices / (double(n - 1) * (m - 1)))));
    std::vector<int> columnSplits(n - 1, 1), rowSplits(m - 1, 1);
    for (int j = 0; j + 1 < m; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            const glm::vec2 n00 = map.node(i, j), n10 = map.node(i + 1, j), n01 = map.node(i, j + 1);
            const double twist = pixels(n00 - n10 - n01 + map.node(i + 1, j + 1));
            const double bend = std::ceil(std::sqrt(twist / (4.0 * kMaxBendPixels)));
            const auto splits = [&](double extent) {
                return std::clamp(static_cast<int>(std::max(bend, std::ceil(extent / kMaxSubQuadPixels))), 1, maxSplits);
            };
            columnSplits[i] = std::max(columnSplits[i], splits(std::max(pixels(n10 - n00), pixels(map.node(i + 1, j + 1) - n01))));
            rowSplits[j] = std::max(rowSplits[j], splits(std::max(pixels(n01 - n00), pixels(map.node(i + 1, j + 1) - n10))));
        }
    const std::vector<double> us = meshAxis(columnSplits), vs = meshAxis(rowSplits);

    Mesh mesh;
    const std::size_t nu = us.size(), nv = vs.size();
    const codec::FootprintField field(map);
    mesh.vertices.reserve(nu * nv * kVertexFloats);
    for (double v : vs)
        for (double u : us) {
            const glm::dvec2 d = map.distort({u, v});
            const glm::dmat2 f = field.inverseJacobian({u, v});
            const glm::dvec2 a = f[0] / double(width), b = f[1] / double(height);
            mesh.vertices.insert(mesh.vertices.end(), {float(d.x), float(d.y), float(u), float(v), float(a.x),
                                                       float(a.y), float(b.x), float(b.y)});
        }
    mesh.indices.reserve((nu - 1) * (nv - 1) * 6);
    for (std::size_t j = 0; j + 1 < nv; ++j)
        for (std::size_t i = 0; i + 1 < nu; ++i) {
            const auto k = static_cast<GLuint>(j * nu + i), right = k + 1, below = static_cast<GLuint>(k + nu);
            mesh.indices.insert(mesh.indices.end(), {k, right, below + 1, k, below + 1, below});
        }
    return mesh;
}

// The encoder's source pyramid at the CPU reference's level sizes ((w + 1) / 2 each way, down to
// 1 x 1): level 0 is the source texture itself, levels 1.. are stacked in one RGBA32F atlas.
constexpr int kMaxPyramidLevels = 32;  // uLevelRect in encode.frag.glsl

struct Pyramid {
    std::vector<std::array<int, 4>> rects;  // per level: x, y in the atlas, width, height
    int atlasWidth = 0, atlasHeight = 0;
};

Pyramid pyramidLayout(int width, int height) {
    Pyramid p;
    p.rects.push_back({0, 0, width, height});
    int y = 0;
    while ((width > 1 || height > 1) && static_cast<int>(p.rects.size()) < kMaxPyramidLevels) {
        width = std::max(1, (width + 1) / 2);
        height = std::max(1, (height + 1) / 2);
        p.rects.push_back({0, y, width, height});
        p.atlasWidth = std::max(p.atlasWidth, width);
        y += height;
    }
    p.atlasHeight = y;
    return p;
}

void setLinearClamp(const GladGLContext& gl) {
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

// Fills the atlas level by level, each from the one above (level 0 is `source`). Reading the atlas
// while drawing into another region of it is defined after glTextureBarrier.
void buildPyramid(Context& context, const GladGLContext& gl, const Pyramid& pyramid, GLuint source, GLuint atlas) {
    if (pyramid.rects.size() < 2) return;
    const GLuint program =
        cachedProgram(context, "pyramid", shaders::kShaderFullscreenVert, shaders::kShaderPyramidFrag);
    GlHandle framebuffer = makeFramebuffer(gl);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, atlas, 0);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error(ErrorCode::Unsupported, "encodeImageGpu: the driver cannot render into the RGBA32F pyramid");
    gl.UseProgram(program);
    gl.Uniform1i(gl.GetUniformLocation(program, "uSource"), 0);
    const GLint sourceRect = gl.GetUniformLocation(program, "uSourceRect");
    const GLint targetRect = gl.GetUniformLocation(program, "uTargetRect");
    gl.BindVertexArray(context.impl().emptyVertexArray);
    gl.ActiveTexture(GL_TEXTURE0);
    for (std::size_t level = 1; level < pyramid.rects.size(); ++level) {
        const auto& from = pyramid.rects[level - 1];
        const auto& to = pyramid.rects[level];
        gl.BindTexture(GL_TEXTURE_2D, level == 1 ? source : atlas);
        gl.Uniform4i(sourceRect, from[0], from[1], from[2], from[3]);
        gl.Uniform4i(targetRect, to[0], to[1], to[2], to[3]);
        gl.Viewport(to[0], to[1], to[2], to[3]);
        gl.TextureBarrier();
        gl.DrawArrays(GL_TRIANGLES, 0, 3);
    }
}

// Tiling, for sources (or their pyramids) over the texture limit: the source is cut into tiles,
// and each tile is drawn from crops of every pyramid level around its core. The levels are the
// full image's (built once, at the CPU reference's sizes), so a crop's texels are the full
// pyramid's texels and a tiled pixel reads exactly what an untiled one would.
//
// A tap lies within half the filter's extent along each footprint edge of the pixel's centre, plus
// a texel for the bilinear filter; the finer of the two blended levels reaches furthest in its own
// texels. The margin every level's crop needs is the largest such reach over the mesh's vertices
// (codec::planFootprint on their footprints), with room for the interpolation in between:
// kMarginSlack of it plus kMarginTexels. Maps with long footprints get wide margins, most get a few
// texels.
constexpr double kMarginSlack = 1.25;
constexpr int kMarginTexels = 3;

int tileMargin(const Mesh& mesh, int width, int height, double uniform) {
    double reach = 0;
    for (std::size_t k = 0; k + kVertexFloats <= mesh.vertices.size(); k += kVertexFloats) {
        const float* f = &mesh.vertices[k + 4];
        const glm::dvec2 a(f[0] * double(width), f[1] * double(height)), b(f[2] * double(width), f[3] * double(height));
        const codec::FootprintPlan plan = codec::planFootprint(a, b, uniform);
        const double scale = std::ldexp(1.0, -static_cast<int>(plan.level));  // level sizes round up: no smaller
        const double rx = 0.5 * (std::abs(a.x) * plan.extent.x + std::abs(b.x) * plan.extent.y);
        const double ry = 0.5 * (std::abs(a.y) * plan.extent.x + std::abs(b.y) * plan.extent.y);
        reach = std::max(reach, std::max(rx, ry) * scale);
    }
    return static_cast<int>(std::ceil(kMarginSlack * reach)) + kMarginTexels;
}

struct TileLevel {
    int x = 0, y = 0, width = 0, height = 0;  // the crop, in the full level's texels
    int atlasX = 0, atlasY = 0;               // where it sits in its texture
};

struct Tile {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the core, in source texels
    std::vector<TileLevel> levels;       // level 0 is its own texture; levels 1.. share an atlas
    int atlasWidth = 1, atlasHeight = 1;
    std::vector<GLuint> indices;  // the mesh triangles that may reach into the core
};

// The crops of every level around core [x0, x1) x [y0, y1) of a width x height source: level 1 at
// the atlas's origin, levels 2.. stacked to its right.
Tile planTile(const Pyramid& pyramid, int margin, int x0, int y0, int x1, int y1) {
    Tile tile{x0, y0, x1, y1, {}, 1, 1, {}};
    const double width = pyramid.rects[0][2], height = pyramid.rects[0][3];
    int stackY = 0, stackWidth = 0;
    for (std::size_t level = 0; level < pyramid.rects.size(); ++level) {
        const int w = pyramid.rects[level][2], h = pyramid.rects[level][3];
        TileLevel crop;
        crop.x = std::max(0, static_cast<int>(std::floor(x0 * (w / width))) - margin);
        crop.y = std::max(0, static_cast<int>(std::floor(y0 * (h / height))) - margin);
        crop.width = std::min(w, static_cast<int>(std::ceil(x1 * (w / width))) + margin) - crop.x;
        crop.height = std::min(h, static_cast<int>(std::ceil(y1 * (h / height))) + margin) - crop.y;
        if (level >= 2) {
            crop.atlasX = tile.levels[1].width;
            crop.atlasY = stackY;
            stackY += crop.height;
            stackWidth = std::max(stackWidth, crop.width);
        }
        tile.levels.push_back(crop);
    }
    if (tile.levels.size() > 1) {
        tile.atlasWidth = tile.levels[1].width + stackWidth;
        tile.atlasHeight = std::max(tile.levels[1].height, stackY);
    }
    return tile;
}

// Splits [0, size) into `count` near-equal parts.
std::vector<int> splitAxis(int size, int count) {
    std::vector<int> cuts;
    for (int i = 0; i <= count; ++i) cuts.push_back(static_cast<int>((static_cast<long long>(size) * i) / count));
    return cuts;
}

// The tiles of the source: the largest near-square cores whose crops fit the limit.
std::vector<Tile> planTiles(const Pyramid& pyramid, int margin, int limit) {
    const int width = pyramid.rects[0][2], height = pyramid.rects[0][3];
    for (int core = std::max(1, limit - 2 * margin - 2);; core = std::max(1, core - std::max(1, core / 16))) {
        const std::vector<int> xs = splitAxis(width, (width + core - 1) / core);
        const std::vector<int> ys = splitAxis(height, (height + core - 1) / core);
        std::vector<Tile> tiles;
        bool fits = true;
        for (std::size_t j = 0; j + 1 < ys.size() && fits; ++j)
            for (std::size_t i = 0; i + 1 < xs.size() && fits; ++i) {
                tiles.push_back(planTile(pyramid, margin, xs[i], ys[j], xs[i + 1], ys[j + 1]));
                const Tile& t = tiles.back();
                fits = t.levels[0].width <= limit && t.levels[0].height <= limit && t.atlasWidth <= limit &&
                       t.atlasHeight <= limit;
            }
        if (fits) return tiles;
        if (core == 1)
            throw Error(ErrorCode::LimitExceeded, "encodeImageGpu: no tiling of the " + std::to_string(width) + "x" +
                                                      std::to_string(height) + " source fits the texture limit " +
                                                      std::to_string(limit));
    }
}

// The tile's core in normalized source coordinates, open-ended at the source's edges (pixels whose
// undistorted centre falls just outside [0, 1] belong to the edge tiles).
std::array<float, 4> tileCore(const Tile& tile, int width, int height) {
    constexpr float kFar = std::numeric_limits<float>::max();
    return {tile.x0 == 0 ? -kFar : float(double(tile.x0) / width), tile.y0 == 0 ? -kFar : float(double(tile.y0) / height),
            tile.x1 == width ? kFar : float(double(tile.x1) / width),
            tile.y1 == height ? kFar : float(double(tile.y1) / height)};
}

// The mesh's triangles whose undistorted bounding box meets the tile's core (the shader discards
// the pixels outside it): each pixel is drawn by exactly one tile, the one whose core holds its
// interpolated undistorted centre.
std::vector<GLuint> tileIndices(const Mesh& mesh, const std::array<float, 4>& core) {
    std::vector<GLuint> out;
    for (std::size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
        float u0 = std::numeric_limits<float>::max(), v0 = u0, u1 = -u0, v1 = -u0;
        for (int c = 0; c < 3; ++c) {
            const float* vertex = &mesh.vertices[std::size_t(mesh.indices[k + c]) * kVertexFloats];
            u0 = std::min(u0, vertex[2]);
            u1 = std::max(u1, vertex[2]);
            v0 = std::min(v0, vertex[3]);
            v1 = std::max(v1, vertex[3]);
        }
        constexpr float kSlack = 1e-5f;  // interpolation may stray a rounding error past the vertices
        if (u1 + kSlack >= core[0] && u0 - kSlack <= core[2] && v1 + kSlack >= core[1] && v0 - kSlack <= core[3])
            out.insert(out.end(), mesh.indices.begin() + k, mesh.indices.begin() + k + 3);
    }
    return out;
}

// Uploads the crop [x, x + width) x [y, y + height) of `pixels` (an image `rowLength` wide with
// `count` channels) into the bound texture at (atlasX, atlasY).
void uploadCrop(const GladGLContext& gl, const float* pixels, int rowLength, int count, const TileLevel& crop) {
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.PixelStorei(GL_UNPACK_ROW_LENGTH, rowLength);
    gl.PixelStorei(GL_UNPACK_SKIP_PIXELS, crop.x);
    gl.PixelStorei(GL_UNPACK_SKIP_ROWS, crop.y);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, crop.atlasX, crop.atlasY, crop.width, crop.height, pixelFormat(count), GL_FLOAT,
                     pixels);
    gl.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    gl.PixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
    gl.PixelStorei(GL_UNPACK_SKIP_ROWS, 0);
}

}  // namespace

namespace {

// One GPU encode: the program, the mesh uploaded once for every pass of four channels, the
// target, and (for sources past the texture limit) the tile plan with the CPU-built pyramid.
class GpuEncoder {
public:
    GpuEncoder(Context& context, const Image& source, const codec::SamplingMap& map, Image& out)
        : m_context(context), m_gl(makeCurrentGl(context)), m_source(source), m_out(out),
          m_pyramid(pyramidLayout(source.width, source.height)), m_mesh(buildMesh(map, out.width, out.height)),
          m_vertexArray(makeVertexArray(m_gl)), m_vertexBuffer(makeBuffer(m_gl)), m_indexBuffer(makeBuffer(m_gl)),
          m_target(m_gl, out.width, out.height, kWhat) {
        m_program = cachedProgram(context, "encode", shaders::kShaderEncodeVert, shaders::kShaderEncodeFrag);
        uploadMesh();
        const int limit = context.textureLimit();
        if (source.width > limit || source.height > limit || m_pyramid.atlasWidth > limit || m_pyramid.atlasHeight > limit)
            planTiling(limit);
    }

    // Channels [first, first + count) of the source into the same channels of the output.
    void pass(int first, int count, GpuTimings& t, Clock::time_point& start) {
        const PassPixels pixels(m_source, first, count);
        if (m_tiles.empty()) drawWhole(pixels, count, t, start);
        else drawTiles(pixels, first, count, t, start);
        m_gl.BindFramebuffer(GL_FRAMEBUFFER, m_target.framebuffer.id());
        readBack(m_gl, m_out, first, count);
        checkGl(m_gl, kWhat);
        t.readbackMs += millisecondsSince(start);
    }

    ~GpuEncoder() {
        m_gl.BindVertexArray(0);
        m_gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    }

private:
    static constexpr const char* kWhat = "encodeImageGpu";

    double uniformSpacing() const {
        return codec::uniformSpacing(m_source.width, m_source.height, m_out.width, m_out.height);
    }
    static constexpr float kFar = std::numeric_limits<float>::max();

    void uploadMesh() {
        m_gl.BindVertexArray(m_vertexArray.id());
        m_gl.BindBuffer(GL_ARRAY_BUFFER, m_vertexBuffer.id());
        m_gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(m_mesh.vertices.size() * sizeof(float)),
                        m_mesh.vertices.data(), GL_STATIC_DRAW);
        m_gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m_indexBuffer.id());
        m_gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(m_mesh.indices.size() * sizeof(GLuint)),
                        m_mesh.indices.data(), GL_STATIC_DRAW);
        m_gl.EnableVertexAttribArray(0);
        constexpr GLsizei kStride = kVertexFloats * sizeof(float);
        m_gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, kStride, nullptr);
        m_gl.EnableVertexAttribArray(1);
        m_gl.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, kStride, reinterpret_cast<const void*>(2 * sizeof(float)));
        m_gl.EnableVertexAttribArray(2);
        m_gl.VertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, kStride, reinterpret_cast<const void*>(4 * sizeof(float)));
        checkGl(m_gl, kWhat);
    }

    // The plan, each tile's share of the mesh, and the pyramid's levels 1.. (built once on the
    // CPU with the reference's own area filter; the GPU then reads crops of them per tile).
    void planTiling(int limit) {
        m_tiles = planTiles(m_pyramid, tileMargin(m_mesh, m_source.width, m_source.height, uniformSpacing()), limit);
        m_levels.reserve(m_pyramid.rects.size());
        for (Tile& tile : m_tiles) tile.indices = tileIndices(m_mesh, tileCore(tile, m_source.width, m_source.height));
        for (std::size_t level = 1; level < m_pyramid.rects.size(); ++level)
            m_levels.push_back(codec::areaDownsample(level == 1 ? m_source : m_levels.back(), m_pyramid.rects[level][2],
                                                     m_pyramid.rects[level][3], 0));
    }

    void setDrawState(GLuint level0, GLuint atlas, const std::vector<std::array<int, 4>>& rects, const std::array<float, 4>& core) {
        const GladGLContext& gl = m_gl;
        gl.BindFramebuffer(GL_FRAMEBUFFER, m_target.framebuffer.id());
        gl.Viewport(0, 0, m_out.width, m_out.height);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, level0);
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, atlas);
        gl.UseProgram(m_program);
        gl.Uniform1i(gl.GetUniformLocation(m_program, "uLevel0"), 0);
        gl.Uniform1i(gl.GetUniformLocation(m_program, "uPyramid"), 1);
        gl.Uniform1i(gl.GetUniformLocation(m_program, "uLevels"), static_cast<GLint>(rects.size()));
        gl.Uniform4iv(gl.GetUniformLocation(m_program, "uLevelRect"), static_cast<GLsizei>(rects.size()), rects[0].data());
        gl.Uniform4f(gl.GetUniformLocation(m_program, "uCore"), core[0], core[1], core[2], core[3]);
        gl.Uniform1f(gl.GetUniformLocation(m_program, "uUniform"), static_cast<float>(uniformSpacing()));
        gl.BindVertexArray(m_vertexArray.id());
    }

    // Upload the source as a float texture and build its area-averaged pyramid on the GPU, then
    // rasterize the whole mesh at the CoNUS resolution.
    void drawWhole(const PassPixels& pixels, int count, GpuTimings& t, Clock::time_point& start) {
        const GladGLContext& gl = m_gl;
        GlHandle texture = makeTexture(gl), atlas = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, texture.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, internalFormat(count), m_source.width, m_source.height);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, m_source.width, m_source.height, pixelFormat(count), GL_FLOAT, pixels.data());
        setLinearClamp(gl);
        gl.BindTexture(GL_TEXTURE_2D, atlas.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, std::max(1, m_pyramid.atlasWidth), std::max(1, m_pyramid.atlasHeight));
        setLinearClamp(gl);
        buildPyramid(m_context, gl, m_pyramid, texture.id(), atlas.id());
        checkGl(gl, kWhat);
        gl.Finish();
        t.uploadMs += millisecondsSince(start);

        setDrawState(texture.id(), atlas.id(), m_pyramid.rects, {-kFar, -kFar, kFar, kFar});
        gl.ClearColor(0, 0, 0, 0);
        gl.Clear(GL_COLOR_BUFFER_BIT);
        gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(m_mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
        checkGl(gl, kWhat);
        gl.Finish();
        t.drawMs += millisecondsSince(start);
    }

    // Per tile: upload the crops of every level around its core, draw its triangles; the shader
    // keeps the pixels of its core.
    void drawTiles(const PassPixels& pixels, int first, int count, GpuTimings& t, Clock::time_point& start) {
        const GladGLContext& gl = m_gl;
        gl.BindFramebuffer(GL_FRAMEBUFFER, m_target.framebuffer.id());
        gl.ClearColor(0, 0, 0, 0);
        gl.Clear(GL_COLOR_BUFFER_BIT);
        std::vector<PassPixels> levelPixels;
        levelPixels.reserve(m_levels.size());
        for (const Image& level : m_levels) levelPixels.emplace_back(level, first, count);
        for (const Tile& tile : m_tiles) {
            if (tile.indices.empty()) continue;
            GlHandle texture = makeTexture(gl), atlas = makeTexture(gl);
            const TileLevel& crop0 = tile.levels[0];
            gl.ActiveTexture(GL_TEXTURE0);
            gl.BindTexture(GL_TEXTURE_2D, texture.id());
            gl.TexStorage2D(GL_TEXTURE_2D, 1, internalFormat(count), crop0.width, crop0.height);
            uploadCrop(gl, pixels.data(), m_source.width, count, crop0);
            setLinearClamp(gl);
            gl.BindTexture(GL_TEXTURE_2D, atlas.id());
            gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, tile.atlasWidth, tile.atlasHeight);
            for (std::size_t level = 1; level < tile.levels.size(); ++level)
                uploadCrop(gl, levelPixels[level - 1].data(), m_pyramid.rects[level][2], count, tile.levels[level]);
            setLinearClamp(gl);
            std::vector<std::array<int, 4>> rects;
            for (std::size_t level = 0; level < tile.levels.size(); ++level) {
                const TileLevel& crop = tile.levels[level];
                rects.push_back({crop.atlasX - crop.x, crop.atlasY - crop.y, m_pyramid.rects[level][2], m_pyramid.rects[level][3]});
            }
            gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m_indexBuffer.id());
            gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(tile.indices.size() * sizeof(GLuint)),
                          tile.indices.data(), GL_STREAM_DRAW);
            checkGl(gl, kWhat);
            gl.Finish();
            t.uploadMs += millisecondsSince(start);

            setDrawState(texture.id(), atlas.id(), rects, tileCore(tile, m_source.width, m_source.height));
            gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(tile.indices.size()), GL_UNSIGNED_INT, nullptr);
            checkGl(gl, kWhat);
            gl.Finish();
            t.drawMs += millisecondsSince(start);
        }
    }

    Context& m_context;
    const GladGLContext& m_gl;
    const Image& m_source;
    Image& m_out;
    const Pyramid m_pyramid;
    const Mesh m_mesh;
    GlHandle m_vertexArray, m_vertexBuffer, m_indexBuffer;
    FloatTarget m_target;
    GLuint m_program = 0;
    std::vector<Tile> m_tiles;  // empty: not tiled
    std::vector<Image> m_levels;
};

}  // namespace

Image encodeImageGpu(Context& context, const Image& source, const codec::SamplingMap& map,
                             const codec::EncodeOptions& options, GpuTimings* timings) {
    checkImage(source, "encodeImageGpu");
    Image out = makeImage(options.width, options.height, source.channels);
    checkTextureSize(context, out.width, out.height, "encodeImageGpu", "output");
    GpuTimings t;
    Clock::time_point start = Clock::now();
    GpuEncoder encoder(context, source, map, out);
    for (int first = 0; first < source.channelCount(); first += kChannelsPerPass)
        encoder.pass(first, std::min(kChannelsPerPass, source.channelCount() - first), t, start);
    if (timings) *timings = t;
    return out;
}

Image decodeImageGpu(Context& context, const Image& conus, const codec::SamplingMap& map,
                             const codec::DecodeOptions& options, GpuTimings* timings) {
    constexpr const char* kWhat = "decodeImageGpu";
    checkImage(conus, kWhat);
    codec::checkDecodeMemory(conus, options.width, options.height, kMaxDecodeBytes, options.pyramid != nullptr);
    if (options.pyramid) codec::checkPyramid(conus, *options.pyramid);
    const codec::View& view = options.view;
    if (!std::isfinite(view.u0) || !std::isfinite(view.u1) || !std::isfinite(view.v0) || !std::isfinite(view.v1) ||
        view.u0 == view.u1 || view.v0 == view.v1 || std::abs(view.u1 - view.u0) > 1e6 ||
        std::abs(view.v1 - view.v0) > 1e6)
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": view (" + std::to_string(view.u0) + ", " +
                                                    std::to_string(view.v0) + ") - (" + std::to_string(view.u1) +
                                                    ", " + std::to_string(view.v1) + ") is empty or not finite");
    Image out = makeImage(options.width, options.height, conus.channels);
    checkTextureSize(context, conus.width, conus.height, kWhat, "CoNUS image");
    checkTextureSize(context, out.width, out.height, kWhat, "output");

    GpuTimings t;
    Clock::time_point start = Clock::now();
    const GladGLContext& gl = makeCurrentGl(context);
    const bool pyramid = options.pyramid != nullptr;
    std::string source = shaders::kShaderDecodeFrag;
    if (pyramid) source.insert(source.find('\n') + 1, "#define DECODE_PYRAMID 1\n");
    const GLuint program =
        cachedProgram(context, pyramid ? "decode/pyramid" : "decode", shaders::kShaderFullscreenVert, source.c_str());

    // The map's nodes, fetched exactly (texelFetch) by the shader.
    GlHandle mapTexture = uploadMapTexture(gl, GL_TEXTURE1, map.columns(), map.rows(), &map.nodes().front().x);
    FloatTarget target(gl, out.width, out.height, kWhat);
    checkGl(gl, kWhat);

    for (int first = 0; first < conus.channelCount(); first += kChannelsPerPass) {
        const int count = std::min(kChannelsPerPass, conus.channelCount() - first);
        GlHandle texture = makeTexture(gl);
        {
            // The image, then (pyramid decode) the pyramid's levels as its mip chain.
            std::vector<PassPixels> pixels;
            pixels.reserve(1 + (pyramid ? options.pyramid->levels.size() : 0));
            pixels.emplace_back(conus, first, count);
            if (pyramid)
                for (const Image& level : options.pyramid->levels) pixels.emplace_back(level, first, count);
            std::vector<TextureLevel> levels{{pixels[0].data(), conus.width, conus.height}};
            if (pyramid)
                for (std::size_t k = 0; k < options.pyramid->levels.size(); ++k)
                    levels.push_back({pixels[k + 1].data(), options.pyramid->levels[k].width,
                                      options.pyramid->levels[k].height});
            gl.ActiveTexture(GL_TEXTURE0);
            gl.BindTexture(GL_TEXTURE_2D, texture.id());
            storeLevels(gl, internalFormat(count), pixelFormat(count), levels);
            checkGl(gl, kWhat);
            gl.Finish();
        }
        t.uploadMs += millisecondsSince(start);

        gl.BindFramebuffer(GL_FRAMEBUFFER, target.framebuffer.id());
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, mapTexture.id());
        gl.UseProgram(program);
        gl.Uniform1i(gl.GetUniformLocation(program, "uConus"), 0);
        gl.Uniform1i(gl.GetUniformLocation(program, "uMap"), 1);
        gl.Uniform4f(gl.GetUniformLocation(program, "uView"), float(view.u0), float(view.v0), float(view.u1),
                     float(view.v1));
        gl.Uniform2f(gl.GetUniformLocation(program, "uOutputSize"), float(out.width), float(out.height));
        gl.BindVertexArray(context.impl().emptyVertexArray);
        gl.DrawArrays(GL_TRIANGLES, 0, 3);
        checkGl(gl, kWhat);
        gl.Finish();
        t.drawMs += millisecondsSince(start);

        readBack(gl, out, first, count);
        checkGl(gl, kWhat);
        t.readbackMs += millisecondsSince(start);
    }
    gl.BindVertexArray(0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (timings) *timings = t;
    return out;
}

Image encodeImage(const Device& device, const Image& source, const codec::SamplingMap& map,
                          const codec::EncodeOptions& options) {
    codec::checkEncodeMemory(source, options.width, options.height);
    return device.run([&] { return codec::encodeImage(source, map, options); },
                      [&](Context& context) { return encodeImageGpu(context, source, map, options); });
}

Image decodeImage(const Device& device, const Image& conus, const codec::SamplingMap& map,
                          const codec::DecodeOptions& options) {
    return device.run([&] { return codec::decodeImage(conus, map, options); },
                      [&](Context& context) { return decodeImageGpu(context, conus, map, options); });
}

}  // namespace conus::gl
