// The map editor of --edit (paper section 3.1, Figure 8), without any GL: a mass-spring grid
// (codec::SpringSystem) painted with a brush at undistorted positions, stepped every frame so the
// grid relaxes live, saved as a CoNUS map file (the layout of `conus map`: density as channel Y,
// one pixel per node) or used to encode the image it was painted over.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "conus/codec/builders/springs.h"
#include "conus/format/container.h"
#include "conus/core/image.h"
#include "conus/core/map_rules.h"

namespace conus::viewer {

inline constexpr int kEditorGrid = map_rules::kDefaultSide;          // particles per side
inline constexpr int kEditorStepsPerFrame = 8;  // solver steps between frames

struct Brush {
    double radius = 0.08;   // normalized, as codec::Stroke
    double strength = 0.5;  // rest spacings at the centre, as codec::Stroke
};

class MapEditor {
public:
    // `source` is the image painted over (linear light), `encoding` what its file held; the encode
    // size defaults to the source's.
    explicit MapEditor(Image source, SourceEncoding encoding = {}, int gridColumns = kEditorGrid,
                       int gridRows = kEditorGrid);

    Brush& brush() { return m_brush; }
    const Brush& brush() const { return m_brush; }
    // Scales the radius (Shift-wheel) or strength ([ ]) within their ranges.
    void scaleRadius(double factor);
    void scaleStrength(double factor);

    // A drag: a stroke at the press, then one each time the cursor has moved a third of the radius.
    void press(glm::dvec2 uv);
    void moveTo(glm::dvec2 uv);
    void release();
    bool painting() const { return m_painting; }
    int strokes() const { return m_strokes; }

    void step(int n = kEditorStepsPerFrame);
    bool stable() const { return m_springs.stable(); }
    void reset();

    const Image& source() const { return m_source; }
    codec::SamplingMap map() const { return m_springs.toMap(); }
    // The map as `conus map` writes it: image = density at the nodes (channel Y), float.
    format::ConusFile mapFile() const;
    // The source encoded through the current map at width x height (CPU reference encoder).
    format::ConusFile encode(int width, int height) const;

private:
    void addStroke(glm::dvec2 uv);
    Image m_source;
    SourceEncoding m_encoding;
    int m_columns, m_rows;
    codec::SpringSystem m_springs;
    Brush m_brush;
    bool m_painting = false;
    glm::dvec2 m_last{0.0};
    int m_strokes = 0;
};

}  // namespace conus::viewer
