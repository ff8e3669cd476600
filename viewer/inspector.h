// The pixel inspector: what lies under the cursor, computed on the CPU from the file itself (not
// read back from the screen, so it shows every channel, Z included, at full precision).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"

namespace conus::viewer {

struct Probe {
    bool inside = false;             // (u,v) within the image
    glm::dvec2 uv{0.0};              // undistorted
    glm::dvec2 distorted{0.0};       // SM(u,v), Equation 1
    glm::ivec2 sourcePixel{0};       // conventional frame pixel
    glm::ivec2 conusPixel{0};        // CoNUS image pixel holding SM(u,v)
    double density = 0;              // det J: samples per area relative to a uniform image
    std::vector<std::string> channels;
    std::vector<float> values;       // the CoNUS image sampled bilinearly at SM(u,v), as decode does
    // Depth images with a camera: the world point conusPixel saw (depth_view.h's worldPoint), or
    // nullopt on the background (then `depthImage` still says the file could give one).
    bool depthImage = false;
    std::optional<glm::dvec3> world;
};

Probe probe(const format::ConusFile& file, const codec::SamplingMap& map, glm::dvec2 uv);

// "u,v=(0.4210,0.3100) ud,vd=(...) density 3.91 (linear 1.98) R=0.51 G=... Z=... P=(x,y,z)"
// (P: the 3-D point of a depth image; "P=background" where its pixel saw nothing)
std::string formatProbe(const Probe& p);

}  // namespace conus::viewer
