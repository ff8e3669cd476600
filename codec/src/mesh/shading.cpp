// The shading rule of mesh renders (shading.h): albedo by vertex colour, texture or grey, then the
// two-sided headlight.
#include "conus/codec/mesh/shading.h"

#include <cmath>

namespace conus::codec {

glm::dvec3 directionToEye(const Camera& camera, glm::dvec3 p) {
    if (camera.projection() == Projection::Orthographic) return -camera.forward();
    const glm::dvec3 d = camera.eye() - p;
    const double length = glm::length(d);
    return length > 0 ? d / length : -camera.forward();
}

glm::vec3 sampleTexture(const Image& texture, glm::vec2 uv) {
    if (texture.empty()) return glm::vec3(kDefaultAlbedo);
    const int w = texture.width, h = texture.height;
    // Texel centres at (i + 0.5) / w; repeat on both axes (GL_LINEAR, GL_REPEAT).
    const double x = double(uv.x) * w - 0.5, y = double(uv.y) * h - 0.5;
    if (!std::isfinite(x) || !std::isfinite(y)) return glm::vec3(kDefaultAlbedo);
    const double fx = std::floor(x), fy = std::floor(y);
    const float tx = float(x - fx), ty = float(y - fy);
    auto wrap = [](double i, int n) { return int(((std::fmod(i, double(n))) + n)) % n; };
    const int x0 = wrap(fx, w), x1 = wrap(fx + 1, w), y0 = wrap(fy, h), y1 = wrap(fy + 1, h);
    const int channels = texture.channelCount();
    auto texel = [&](int xi, int yi) {
        if (channels < 3) return glm::vec3(texture.at(xi, yi, 0));
        return glm::vec3(texture.at(xi, yi, 0), texture.at(xi, yi, 1), texture.at(xi, yi, 2));
    };
    const glm::vec3 top = texel(x0, y0) * (1 - tx) + texel(x1, y0) * tx;
    const glm::vec3 bottom = texel(x0, y1) * (1 - tx) + texel(x1, y1) * tx;
    return top * (1 - ty) + bottom * ty;
}

glm::vec3 meshAlbedo(const Mesh& mesh, std::size_t triangle, float b1, float b2) {
    const std::uint32_t* corner = &mesh.indices[triangle * 3];
    const float b0 = 1.0f - b1 - b2;
    if (!mesh.colours.empty())
        return mesh.colours[corner[0]] * b0 + mesh.colours[corner[1]] * b1 + mesh.colours[corner[2]] * b2;
    if (mesh.texture && !mesh.uvs.empty())
        return sampleTexture(*mesh.texture, mesh.uvs[corner[0]] * b0 + mesh.uvs[corner[1]] * b1 + mesh.uvs[corner[2]] * b2);
    return glm::vec3(kDefaultAlbedo);
}

std::vector<std::string> meshChannelNames() { return {kMeshChannels.begin(), kMeshChannels.end()}; }

}  // namespace conus::codec
