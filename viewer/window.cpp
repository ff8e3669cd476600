#include "window.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <optional>

#include "conus/core/error.h"

namespace conus::viewer {
namespace {

// GLFW key + modifiers -> the key table's chord; nullopt for keys the table does not name.
std::optional<KeyChord> chordOf(int key, int mods) {
    KeyChord chord;
    chord.shift = (mods & GLFW_MOD_SHIFT) != 0;
    chord.ctrl = (mods & GLFW_MOD_CONTROL) != 0;
    if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) chord.key = std::string(1, char('A' + key - GLFW_KEY_A));
    else if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) chord.key = std::string(1, char('0' + key - GLFW_KEY_0));
    else if (key == GLFW_KEY_EQUAL && chord.shift) { chord.key = "+"; chord.shift = false; }
    else if (key == GLFW_KEY_EQUAL) chord.key = "=";
    else if (key == GLFW_KEY_KP_ADD) chord.key = "+";
    else if (key == GLFW_KEY_MINUS || key == GLFW_KEY_KP_SUBTRACT) chord.key = "-";
    else if (key == GLFW_KEY_LEFT_BRACKET) chord.key = "[";
    else if (key == GLFW_KEY_RIGHT_BRACKET) chord.key = "]";
    else if (key == GLFW_KEY_TAB) chord.key = "Tab";
    else if (key == GLFW_KEY_F5) chord.key = "F5";
    else if (key == GLFW_KEY_LEFT) chord.key = "Left";
    else if (key == GLFW_KEY_RIGHT) chord.key = "Right";
    else if (key == GLFW_KEY_UP) chord.key = "Up";
    else if (key == GLFW_KEY_DOWN) chord.key = "Down";
    else if (key == GLFW_KEY_PAGE_UP) chord.key = "PageUp";
    else if (key == GLFW_KEY_PAGE_DOWN) chord.key = "PageDown";
    else if (key == GLFW_KEY_ESCAPE) chord.key = "Escape";
    else return std::nullopt;
    return chord;
}

MouseButton buttonOf(int button) {
    return button == GLFW_MOUSE_BUTTON_LEFT ? MouseButton::Left
           : button == GLFW_MOUSE_BUTTON_RIGHT ? MouseButton::Right
                                               : MouseButton::Middle;
}

// GLFW calls back with the window's user pointer.
Window& windowOf(GLFWwindow* w) { return *static_cast<Window*>(glfwGetWindowUserPointer(w)); }

}  // namespace

Window::Window(int width, int height, bool vsync, InputSink& input) : m_input(input) {
    glfwSetErrorCallback([](int, const char* text) { std::fprintf(stderr, "conus-view: GLFW: %s\n", text); });
    if (!glfwInit())
        throw Error(ErrorCode::Unsupported, "cannot open a window (no display? run under xvfb-run, or use --screenshot)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    m_window = glfwCreateWindow(width, height, "conus-view", nullptr, nullptr);
    if (!m_window) {
        glfwTerminate();
        throw Error(ErrorCode::Unsupported, "cannot create a GL 4.5 core window");
    }
    glfwMakeContextCurrent(m_window);
    glfwSwapInterval(vsync ? 1 : 0);
    glfwSetWindowUserPointer(m_window, this);
    glfwSetCursorPosCallback(m_window, [](GLFWwindow* w, double x, double y) {
        Window& self = windowOf(w);
        self.m_input.cursor(glm::dvec2(x, y) * self.framebufferScale());
    });
    glfwSetMouseButtonCallback(m_window, [](GLFWwindow* w, int button, int action, int mods) {
        windowOf(w).m_input.button(buttonOf(button), action == GLFW_PRESS,
                                   {(mods & GLFW_MOD_SHIFT) != 0, (mods & GLFW_MOD_CONTROL) != 0});
    });
    glfwSetScrollCallback(m_window, [](GLFWwindow* w, double, double dy) {
        windowOf(w).m_input.scroll(dy, glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                                           glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS);
    });
    glfwSetKeyCallback(m_window, [](GLFWwindow* w, int key, int, int action, int mods) {
        if (action == GLFW_RELEASE) return;
        if (const auto chord = chordOf(key, mods)) windowOf(w).m_input.key(*chord);
    });
    try {
        m_context = renderers::adoptCurrentContext(glfwGetProcAddress);
    } catch (...) {
        glfwDestroyWindow(m_window);
        glfwTerminate();
        throw;
    }
}

Window::~Window() {
    m_context.reset();  // before the window's GL context goes
    glfwDestroyWindow(m_window);
    glfwTerminate();
}

glm::dvec2 Window::framebufferScale() const {
    int ww = 1, wh = 1, fw = 1, fh = 1;
    glfwGetWindowSize(m_window, &ww, &wh);
    glfwGetFramebufferSize(m_window, &fw, &fh);
    return {double(fw) / std::max(ww, 1), double(fh) / std::max(wh, 1)};
}

std::pair<int, int> Window::framebufferSize() const {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(m_window, &fw, &fh);
    return {fw, fh};
}

void Window::setTitle(const std::string& title) { glfwSetWindowTitle(m_window, title.c_str()); }
void Window::swap() { glfwSwapBuffers(m_window); }
void Window::poll() { glfwPollEvents(); }
void Window::wait(double seconds) { glfwWaitEventsTimeout(seconds); }
bool Window::shouldClose() const { return glfwWindowShouldClose(m_window) != 0; }
void Window::close() { glfwSetWindowShouldClose(m_window, GLFW_TRUE); }

}  // namespace conus::viewer
