// conus-view's input as the window reports it, in framebuffer pixels (x right, y down), without
// GLFW: the controller (controller.h) takes it, and so do scripts and tests.
#pragma once

#include <glm/glm.hpp>

#include "actions.h"

namespace conus::viewer {

enum class MouseButton { Left, Right, Middle };

struct Modifiers {
    bool shift = false, ctrl = false;
};

class InputSink {
public:
    virtual ~InputSink() = default;
    virtual void cursor(glm::dvec2 pixel) = 0;
    virtual void button(MouseButton button, bool press, Modifiers modifiers) = 0;
    virtual void scroll(double notches, bool shift) = 0;
    virtual void key(const KeyChord& chord) = 0;
};

}  // namespace conus::viewer
