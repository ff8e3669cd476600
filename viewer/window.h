// conus-view's window: GLFW (GL 4.5 core through GLX), its context adopted by the renderers, and
// GLFW's events turned into the GL-free input of input.h. The only file that includes GLFW.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include <glm/glm.hpp>

#include "conus/renderers/context.h"
#include "input.h"

struct GLFWwindow;

namespace conus::viewer {

class Window {
public:
    // Opens the window and adopts its context. Throws conus::Error(Unsupported) with the reason
    // (no display, no GL 4.5 core).
    Window(int width, int height, bool vsync, InputSink& input);
    ~Window();
    Window(const Window&) = delete;
    Window& operator=(const Window&) = delete;

    renderers::Context& context() { return *m_context; }
    std::pair<int, int> framebufferSize() const;
    void setTitle(const std::string& title);
    void swap();
    void poll();
    void wait(double seconds);  // until an event or the timeout
    bool shouldClose() const;
    void close();

private:
    glm::dvec2 framebufferScale() const;
    GLFWwindow* m_window = nullptr;
    InputSink& m_input;
    std::unique_ptr<renderers::Context> m_context;
};

}  // namespace conus::viewer
