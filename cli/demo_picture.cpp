#include "demo_picture.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "conus/imageio/text.h"

namespace conus::cli {
namespace {

void fillRect(Image& img, int x0, int y0, int x1, int y1, const float rgb[3]) {
    for (int y = std::max(0, y0); y < std::min(img.height, y1); ++y)
        for (int x = std::max(0, x0); x < std::min(img.width, x1); ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y, c) = rgb[c];
}

// A face-like figure: skin ellipse, eyes with pupils, a mouth, and hair of fine stripes whose
// period (`hairPeriod` px) is what a low sampling rate loses first.
void drawFace(Image& img, double cx, double cy, double radius, double hairPeriod, double hue) {
    const float skin[3] = {static_cast<float>(0.85 - 0.2 * hue), static_cast<float>(0.66 - 0.15 * hue),
                           static_cast<float>(0.52 - 0.1 * hue)};
    const int x0 = std::max(0, int(cx - 1.3 * radius)), x1 = std::min(img.width, int(cx + 1.3 * radius));
    const int y0 = std::max(0, int(cy - 1.5 * radius)), y1 = std::min(img.height, int(cy + 1.4 * radius));
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const double dx = (x + 0.5 - cx) / radius, dy = (y + 0.5 - cy) / (1.25 * radius);
            const double r2 = dx * dx + dy * dy;
            if (r2 > 1.0) continue;
            float rgb[3] = {skin[0], skin[1], skin[2]};
            // Soft shading so the face is not flat.
            const float shade = static_cast<float>(1.0 - 0.25 * r2);
            for (float& c : rgb) c *= shade;
            // Hair: the top of the head, stripes at a slant.
            if (dy < -0.45) {
                const double s = std::sin(2 * std::numbers::pi * (x + 0.35 * y) / hairPeriod);
                const float h = static_cast<float>(0.15 + 0.12 * s);
                rgb[0] = h + 0.1f * static_cast<float>(hue);
                rgb[1] = h;
                rgb[2] = h * 0.8f;
            }
            // Eyes with pupils and a glint.
            for (double side : {-1.0, 1.0}) {
                const double ex = dx - 0.38 * side, ey = dy + 0.1;
                const double e2 = (ex * ex) / 0.03 + (ey * ey) / 0.012;
                if (e2 < 1.0) {
                    rgb[0] = rgb[1] = rgb[2] = 0.95f;
                    const double p2 = (ex * ex + ey * ey) / 0.004;
                    if (p2 < 1.0) rgb[0] = rgb[1] = rgb[2] = 0.05f;
                    if ((ex - 0.02) * (ex - 0.02) + (ey + 0.02) * (ey + 0.02) < 0.0003) rgb[0] = rgb[1] = rgb[2] = 1.0f;
                }
            }
            // Mouth: a thin arc.
            const double my = dy - 0.42 - 0.5 * dx * dx;
            if (std::abs(dx) < 0.35 && std::abs(my) < 0.035) {
                rgb[0] = 0.55f;
                rgb[1] = 0.12f;
                rgb[2] = 0.15f;
            }
            for (int c = 0; c < 3; ++c) img.at(x, y, c) = rgb[c];
        }
}

// Zone plate: cos(pi * r^2 / period^2 ...) whose local frequency grows linearly with the radius
// up to `maxFrequency` cycles per pixel at `radius`.
void drawZonePlate(Image& img, double cx, double cy, double radius, double maxFrequency) {
    const double a = std::numbers::pi * maxFrequency / radius;
    for (int y = std::max(0, int(cy - radius)); y < std::min(img.height, int(cy + radius)); ++y)
        for (int x = std::max(0, int(cx - radius)); x < std::min(img.width, int(cx + radius)); ++x) {
            const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
            const double r2 = dx * dx + dy * dy;
            if (r2 > radius * radius) continue;
            const float v = static_cast<float>(0.5 + 0.45 * std::cos(a * r2));
            img.at(x, y, 0) = v;
            img.at(x, y, 1) = v;
            img.at(x, y, 2) = v;
        }
}

}  // namespace

Image makeDemoPicture(int size) {
    Image img = makeImage(size, size, {"R", "G", "B"});
    const double s = size / 4096.0;  // every length below is given for 4096 px and scaled

    // Background: a smooth sky-to-ground gradient with gentle low-frequency variation.
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const double u = (x + 0.5) / size, v = (y + 0.5) / size;
            const double wave = 0.04 * std::sin(6.0 * u + 3.0 * v) * std::cos(5.0 * v - 2.0 * u);
            img.at(x, y, 0) = static_cast<float>(0.30 + 0.35 * v + wave);
            img.at(x, y, 1) = static_cast<float>(0.45 + 0.20 * v + wave);
            img.at(x, y, 2) = static_cast<float>(0.70 - 0.30 * v + wave);
        }

    // Context: faces scattered around, large captions, a coarse zone plate.
    std::mt19937 random(20101);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const double faces[][2] = {{0.10, 0.72}, {0.45, 0.85}, {0.88, 0.20}, {0.55, 0.12}, {0.12, 0.12}, {0.90, 0.90}};
    for (const auto& f : faces)
        drawFace(img, f[0] * size, f[1] * size, (110 + 60 * uniform(random)) * s, 6.0 * s, uniform(random));
    drawZonePlate(img, 0.33 * size, 0.72 * size, 300 * s, 0.25);
    const float ink[3] = {0.05f, 0.05f, 0.08f}, paper[3] = {0.96f, 0.95f, 0.90f}, white[3] = {1, 1, 1};
    imageio::drawText(img, int(0.40 * size), int(0.05 * size), int(110 * s), "CoNUS demo", white);
    imageio::drawText(img, int(0.62 * size), int(0.40 * size), int(64 * s), "context is sampled sparsely", white);

    // Focus 1 at (0.28, 0.30): fine print on a panel, 15-26 px type.
    const int px = int(0.28 * size), py = int(0.30 * size), half = int(270 * s);
    fillRect(img, px - half, py - half, px + half, py + half, paper);
    const char* lines[] = {"The flexible pinhole camera", "samples regions of interest",
                           "at a higher rate. This fine", "print is readable where the",
                           "sampling map magnifies, and", "lost in a uniform image of",
                           "the same pixel count.", "0123456789 ABCDEFGHIJKLM", "nopqrstuvwxyz !?#%&*+-=",
                           "Equation 1: bilinear lookup", "of the sampling map SM."};
    int line = 0, baseline = py - half + int(40 * s);
    for (const char* text : lines) {
        const int fontSize = int((26 - (line % 4) * 3) * s);
        imageio::drawText(img, px - half + int(20 * s), baseline, std::max(6, fontSize), text, ink);
        baseline += std::max(8, int(fontSize * 1.45));
        ++line;
    }

    // Focus 2 at (0.70, 0.66): a zone plate up to 0.45 cycles/pixel beside a small face.
    drawZonePlate(img, 0.70 * size, 0.66 * size, 190 * s, 0.45);
    drawFace(img, 0.70 * size + 200 * s, 0.66 * size + 150 * s, 70 * s, 3.0 * s, 0.3);

    for (float& v : img.pixels) v = std::clamp(v, 0.0f, 1.0f);
    return img;
}

}  // namespace conus::cli
