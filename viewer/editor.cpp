#include "editor.h"

#include <algorithm>

#include "conus/codec/image/encode.h"
#include "conus/codec/conus_file.h"

namespace conus::viewer {

MapEditor::MapEditor(Image source, SourceEncoding encoding, int gridColumns, int gridRows)
    : m_source(std::move(source)), m_encoding(std::move(encoding)), m_columns(gridColumns), m_rows(gridRows), m_springs(gridColumns, gridRows) {}

void MapEditor::scaleRadius(double factor) { m_brush.radius = std::clamp(m_brush.radius * factor, 0.01, 1.0); }
void MapEditor::scaleStrength(double factor) { m_brush.strength = std::clamp(m_brush.strength * factor, 0.02, 20.0); }

void MapEditor::addStroke(glm::dvec2 uv) {
    codec::Stroke stroke;
    stroke.u = std::clamp(uv.x, 0.0, 1.0);
    stroke.v = std::clamp(uv.y, 0.0, 1.0);
    stroke.radius = m_brush.radius;
    stroke.strength = m_brush.strength;
    m_springs.addStroke(stroke);
    m_last = uv;
    ++m_strokes;
}

void MapEditor::press(glm::dvec2 uv) {
    m_painting = true;
    addStroke(uv);
}

void MapEditor::moveTo(glm::dvec2 uv) {
    // Strokes persist once painted, so spacing them by a fraction of the radius keeps a drag's
    // strength independent of how often the mouse reports.
    if (m_painting && glm::length(uv - m_last) >= m_brush.radius / 3) addStroke(uv);
}

void MapEditor::release() { m_painting = false; }

void MapEditor::step(int n) { m_springs.step(n); }

void MapEditor::reset() {
    m_springs = codec::SpringSystem(m_columns, m_rows);
    m_strokes = 0;
    m_painting = false;
}

format::ConusFile MapEditor::mapFile() const { return codec::makeMapFile(map()); }

format::ConusFile MapEditor::encode(int width, int height) const {
    const codec::SamplingMap map = this->map();
    codec::EncodeOptions options;
    options.width = width;
    options.height = height;
    format::ConusFile file =
        codec::makeImageFile(codec::encodeImage(m_source, map, options), map, m_source.width, m_source.height, m_encoding);
    file.pixelType = format::PixelType::Half;
    return file;
}

}  // namespace conus::viewer
