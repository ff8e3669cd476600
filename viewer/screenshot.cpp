#include "screenshot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "conus/renderers/backend.h"
#include "conus/renderers/view_renderer.h"
#include "depth_view.h"
#include "document.h"
#include "conus/imageio/image_file.h"
#include "view_state.h"
#include "overlay.h"
#include "scene.h"
#include "scene_state.h"

namespace conus::viewer {

constexpr int kDefaultMaxSide = 2048;
constexpr int kSceneWidth = 640, kSceneHeight = 480;  // a 3-D mode's screenshot without --size

namespace {

// A 3-D mode's first frame, as its window shows it (the CoNUS frame through the sRGB curve): the
// scene's home camera and the --focus foci (a baked asset's own maps).
int sceneScreenshot(const Options& options) {
    try {
        const int width = options.width > 0 ? options.width : kSceneWidth;
        const int height = options.height > 0 ? options.height : kSceneHeight;
        const renderers::Device device = renderers::Device::choose(parseEnum<renderers::Backend>(options.backend), renderers::CpuPath::None, "the viewer's screenshot");
        renderers::Context& context = device.context();
        const std::unique_ptr<Scene> scene = openScene(options, context);
        const SceneState state(scene->centre(), scene->radius(), options.foci, scene->home());
        const double aspect = double(width) / height;
        const codec::SamplingMap map = scene->throughMap() ? state.map(aspect) : codec::SamplingMap::identity(2, 2);
        const Image frame = scene->render(state.camera(aspect), map, state.conus(), width, height);
        Image rgb = makeImage(width, height, {"R", "G", "B"});
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = frame.at(x, y, c);
        imageio::writeImageFile(options.screenshot, rgb);
        std::printf("wrote %s: %dx%d, the first frame of %s (%s)\n", options.screenshot.c_str(), width, height,
                    scene->name().c_str(), context.renderer().c_str());
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "conus-view: %s\n", e.what());
        return 1;
    }
}

}  // namespace

int runScreenshot(const Options& options) {
    if (options.sceneKind != SceneKind::None) return sceneScreenshot(options);
    const Document doc = loadDocument(options.files.front(), options.foci);
    if (!doc.ok()) {
        std::fprintf(stderr, "conus-view: %s\n", doc.error.c_str());
        return 1;
    }
    try {
        codec::View view = options.view.value_or(codec::View{});
        int width = options.width, height = options.height;
        if (width > 0) {
            // The window's way: the view as large as fits, letterboxed, never stretched.
            ViewState state(width, height, doc.sourceWidth(), doc.sourceHeight());
            state.showView(view);
            view = state.view();
        } else {
            // The view at source resolution, shrunk to fit kDefaultMaxSide.
            const double w = std::abs(view.u1 - view.u0) * doc.sourceWidth();
            const double h = std::abs(view.v1 - view.v0) * doc.sourceHeight();
            const double scale = std::min(1.0, kDefaultMaxSide / std::max(w, h));
            width = std::max(1, static_cast<int>(std::lround(w * scale)));
            height = std::max(1, static_cast<int>(std::lround(h * scale)));
        }
        const renderers::Device device = renderers::Device::choose(parseEnum<renderers::Backend>(options.backend), renderers::CpuPath::None, "the viewer's screenshot");
        renderers::Context& context = device.context();
        renderers::ViewRenderer renderer(context);
        const bool depth = options.depthPicture && hasDepth(*doc.file);
        if (options.depthPicture && !depth) std::fprintf(stderr, "conus-view: %s has no Z channel: showing its colour\n", doc.path.c_str());
        renderer.setImage(depth ? depthPicture(*doc.file) : *doc.file);
        if (!options.uniform.empty()) renderer.setUniform(uniformBaseline(options.uniform));
        std::vector<renderers::OverlayPlacement> overlays;
        if (options.helpOverlay) {
            renderer.setOverlay(kHelpSlot, helpPanel(KeyTable::View));
            overlays.push_back({kHelpSlot, kOverlayMargin, kOverlayMargin});
        }
        if (options.statusBar) {
            char text[160];
            std::snprintf(text, sizeof text, "%s | %s | %dx%d", std::filesystem::path(doc.path).filename().string().c_str(),
                          depth ? kDepthPictureMode : enumName(options.display.mode), width, height);
            const Image bar = statusPanel(text, width);
            renderer.setOverlay(kStatusSlot, bar);
            overlays.push_back({kStatusSlot, 0, height - bar.height});
        }
        const Image frame = renderer.renderToImage(view, width, height, options.display, overlays);
        imageio::WriteOptions write;
        write.meaning = imageio::PixelMeaning::Display;  // the framebuffer: already what the screen shows
        imageio::writeImageFile(options.screenshot, frame, write);
        std::printf("wrote %s: %dx%d, %s view of %s (%s)\n", options.screenshot.c_str(), width, height,
                    depth ? kDepthPictureMode : enumName(options.display.mode), doc.path.c_str(), context.renderer().c_str());
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "conus-view: %s\n", e.what());
        return 1;
    }
}

}  // namespace conus::viewer
