// The map builders side by side on the same photographs and foci (bench/notes/2026-11-27-map-builders.md):
// `map_builders OUT_DIR [PHOTO...]`. For each photograph of bench/quality.py (its regions as foci of
// k = 4, at 1/16 of the pixels) and each builder (bounded: the default; Moser's flow; optimal
// transport), prints one markdown row: build time, largest and 99th-percentile cell anisotropy,
// the magnification each focus reached, and PSNR gains against the uniform image of the same pixel
// count, whole frame and inside the regions, in linear light and on 8-bit sRGB, and the tile loss
// outside the regions on 8-bit sRGB (95th percentile and worst). Writes each map to
// OUT_DIR/<photo>-<builder>.exr and a picture of its density with its grid, as the CoNUS image
// holds them, to OUT_DIR/<photo>-<builder>.png.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/map_measures.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/format/container.h"
#include "conus/imageio/image_file.h"

using namespace conus;

namespace {

struct Photo {
    std::string name, path;
    std::vector<glm::dvec3> regions;  // u, v, r (r a fraction of the width)
};

const std::string kSkimage = "/usr/lib/python3/dist-packages/skimage/data/";
const std::string kMate = "/usr/share/backgrounds/mate/nature/";
// The photographs and regions of bench/quality.py.
const std::vector<Photo> kPhotos = {
    {"astronaut", kSkimage + "astronaut.png", {{0.44, 0.23, 0.08}, {0.33, 0.75, 0.06}}},
    {"chelsea", kSkimage + "chelsea.png", {{0.37, 0.38, 0.07}, {0.71, 0.45, 0.07}}},
    {"motorcycle", kSkimage + "motorcycle_left.png", {{0.55, 0.62, 0.08}, {0.72, 0.31, 0.05}}},
    {"ladybird", kMate + "LadyBird.jpg", {{0.70, 0.50, 0.05}}},
    {"dandelion", kMate + "TwoWings.jpg", {{0.50, 0.45, 0.07}, {0.74, 0.40, 0.06}}},
    {"garden", kMate + "Garden.jpg", {{0.55, 0.55, 0.09}}},
};
constexpr int kMaxWidth = 1280;
constexpr double kK = 4.0;

// Colour channels only, 8-bit sRGB as a viewer shows them.
Image srgb8(const Image& linear) {
    Image out = imageio::displayEncoded(linear);
    for (float& v : out.pixels) v = std::round(std::clamp(v, 0.0f, 1.0f) * 255.0f) / 255.0f;
    return out;
}

// PSNR (peak 1) of `a` against `reference` over the pixels `inside` accepts (all colour channels).
template <class Inside>
double psnr(const Image& a, const Image& reference, Inside inside) {
    const int channels = std::min(3, reference.channelCount());
    double sum = 0.0;
    std::size_t count = 0;
    for (int y = 0; y < reference.height; ++y)
        for (int x = 0; x < reference.width; ++x) {
            if (!inside(x, y)) continue;
            for (int c = 0; c < channels; ++c) {
                const double d = a.at(x, y, c) - reference.at(x, y, c);
                sum += d * d;
            }
            count += channels;
        }
    return 10.0 * std::log10(1.0 / std::max(sum / double(count), 1e-20));
}

struct Gains {
    double frame = 0, roi = 0;
    double tileP95 = 0, tileWorst = 0;  // tile loss outside the regions (dB)
};

// Tile loss (bench/quality.py's): tiles of max(W, H) / 32 pixels touching no region, loss
// 10 log10((mse + e) / (mse_uniform + e)), e = (2/255)^2; its 95th percentile and worst.
void tileLoss(const Image& conus, const Image& uniform, const Image& source, const Photo& photo, Gains& g) {
    const int tile = std::max(source.width, source.height) / 32, channels = std::min(3, source.channelCount());
    const double e = (2.0 / 255) * (2.0 / 255), w = source.width;
    std::vector<double> losses;
    for (int ty = 0; ty + 1 <= source.height / tile; ++ty)
        for (int tx = 0; tx + 1 <= source.width / tile; ++tx) {
            bool touches = false;
            for (const glm::dvec3& r : photo.regions) {
                const double cx = r.x * w, cy = r.y * source.height;
                const double nx = std::clamp(cx, double(tx * tile), double((tx + 1) * tile));
                const double ny = std::clamp(cy, double(ty * tile), double((ty + 1) * tile));
                touches = touches || std::hypot(nx - cx, ny - cy) <= r.z * w;
            }
            if (touches) continue;
            double mse = 0, mseUniform = 0;
            for (int y = ty * tile; y < (ty + 1) * tile; ++y)
                for (int x = tx * tile; x < (tx + 1) * tile; ++x)
                    for (int c = 0; c < channels; ++c) {
                        const double s = source.at(x, y, c);
                        mse += (conus.at(x, y, c) - s) * (conus.at(x, y, c) - s);
                        mseUniform += (uniform.at(x, y, c) - s) * (uniform.at(x, y, c) - s);
                    }
            const double n = double(tile) * tile * channels;
            losses.push_back(10 * std::log10((mse / n + e) / (mseUniform / n + e)));
        }
    std::sort(losses.begin(), losses.end());
    g.tileP95 = losses[losses.size() * 95 / 100];
    g.tileWorst = losses.back();
}

Gains gains(const Image& conus, const Image& uniform, const Image& source, const Photo& photo) {
    const double w = source.width;
    const auto inRoi = [&](int x, int y) {
        for (const glm::dvec3& r : photo.regions)
            if (std::hypot(x + 0.5 - r.x * w, y + 0.5 - r.y * source.height) <= r.z * w) return true;
        return false;
    };
    const auto all = [](int, int) { return true; };
    Gains g{psnr(conus, source, all) - psnr(uniform, source, all), psnr(conus, source, inRoi) - psnr(uniform, source, inRoi)};
    tileLoss(conus, uniform, source, photo, g);
    return g;
}

// The map as the CoNUS image sees it: each pixel (a distorted point) coloured by log2 of the
// density at its undistorted point (blue: sparse, white: 1, red: dense, saturating at 1/16 and 16),
// with every fourth grid line in black: where the grid cells went.
Image densityOverlay(const codec::SamplingMap& map, int width, int height) {
    Image picture = makeImage(width, height, {"R", "G", "B"});
    const double lines = 4.0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const glm::dvec2 p = map.undistort({(x + 0.5) / width, (y + 0.5) / height});
            const double t = std::clamp(std::log2(map.density(p)) / 4.0, -1.0, 1.0);
            float rgb[3] = {1.0f, 1.0f, 1.0f};
            if (t > 0) rgb[1] = rgb[2] = static_cast<float>(1.0 - t);
            else rgb[0] = rgb[1] = static_cast<float>(1.0 + t);
            const double gu = p.x * (map.columns() - 1) / lines, gv = p.y * (map.rows() - 1) / lines;
            // A line where the grid coordinate crosses a multiple of `lines`, about one pixel wide.
            const glm::dvec2 q = map.undistort({(x + 1.5) / width, (y + 1.5) / height});
            if (std::floor(gu) != std::floor(q.x * (map.columns() - 1) / lines) ||
                std::floor(gv) != std::floor(q.y * (map.rows() - 1) / lines))
                rgb[0] = rgb[1] = rgb[2] = 0.0f;
            for (int c = 0; c < 3; ++c) picture.at(x, y, c) = rgb[c];
        }
    return picture;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: map_builders OUT_DIR [PHOTO...]\n");
        return 2;
    }
    const std::string out = argv[1];
    const std::vector<std::string> only(argv + 2, argv + argc);
    const struct {
        const char* name;
        codec::DensityBuilder builder;
    } builders[] = {{"bounded", codec::DensityBuilder::Bounded}, {"flow", codec::DensityBuilder::Flow}, {"transport", codec::DensityBuilder::Transport}};
    std::printf("| photo | builder | build ms | max aniso | p99 aniso | reached k | frame dB linear | ROI dB linear | frame dB sRGB | ROI dB sRGB | tile loss p95 / worst, sRGB |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const Photo& photo : kPhotos) {
        if (!only.empty() && std::find(only.begin(), only.end(), photo.name) == only.end()) continue;
        Image source = imageio::readImageFile(photo.path).image;
        if (source.width > kMaxWidth) {
            const int h = static_cast<int>(std::lround(double(source.height) * kMaxWidth / source.width));
            source = codec::areaDownsample(source, kMaxWidth, h);
        }
        const int w = source.width / 4, h = source.height / 4;
        const Image uniform = codec::resizeBilinear(codec::areaDownsample(source, w, h), codec::View{}, source.width, source.height);
        const Image source8 = srgb8(source), uniform8 = srgb8(uniform);
        std::vector<codec::Focus> foci;
        for (const glm::dvec3& r : photo.regions) foci.push_back({r.x, r.y, r.z, kK});
        for (const auto& b : builders) {
            codec::FociOptions options;
            options.aspect = double(source.width) / source.height;
            options.builder = b.builder;
            const auto t0 = std::chrono::steady_clock::now();
            const codec::SamplingMap map = codec::buildFociMap(foci, options);
            const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            std::vector<double> cells;
            for (int j = 0; j + 1 < map.rows(); ++j)
                for (int i = 0; i + 1 < map.columns(); ++i)
                    cells.push_back(codec::anisotropy(map.jacobian({(i + 0.5) / (map.columns() - 1), (j + 0.5) / (map.rows() - 1)}), options.aspect));
            std::sort(cells.begin(), cells.end());
            const std::vector<double> reached = codec::reachedMagnification(map, foci);
            std::string reachedText;
            for (double r : reached) reachedText += (reachedText.empty() ? "" : ", ") + std::to_string(r).substr(0, 4);
            codec::EncodeOptions encode;
            encode.width = w;
            encode.height = h;
            codec::DecodeOptions decode;
            decode.width = source.width;
            decode.height = source.height;
            const Image decoded = codec::decodeImage(codec::encodeImage(source, map, encode), map, decode);
            const Gains linear = gains(decoded, uniform, source, photo), display = gains(srgb8(decoded), uniform8, source8, photo);
            std::printf("| %s | %s | %.0f | %.1f | %.1f | %s | %+.2f | %+.2f | %+.2f | %+.2f | %.2f / %.2f |\n", photo.name.c_str(),
                        b.name, ms, cells.back(), cells[cells.size() * 99 / 100], reachedText.c_str(), linear.frame, linear.roi,
                        display.frame, display.roi, display.tileP95, display.tileWorst);
            std::fflush(stdout);
            format::ConusFile file = codec::makeMapFile(map, codec::toAnalytic(foci, options.composition));
            file.sourceWidth = source.width;
            file.sourceHeight = source.height;
            format::writeConusFile(out + "/" + photo.name + "-" + b.name + ".exr", file);
            imageio::WriteOptions asDrawn;
            asDrawn.meaning = imageio::PixelMeaning::Display;
            imageio::writeImageFile(out + "/" + photo.name + "-" + b.name + ".png",
                                    densityOverlay(map, 480, static_cast<int>(std::lround(480.0 * source.height / source.width))), asDrawn);
        }
    }
    return 0;
}
