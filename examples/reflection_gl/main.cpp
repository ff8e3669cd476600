// A reflection asset drawn by a GL program of its own, with the GLSL CoNUS installs
// (docs/reflections-in-your-renderer.md): a headless EGL context (Mesa's surfaceless platform),
// the asset read by conus's reader, its six faces uploaded as the includes expect
// (conus/codec/depth/glsl_interface.h), one full-screen pass of the installed reflection.frag.glsl
// (which includes equation1.inc.glsl and intersect.inc.glsl), the frame written with conus's
// image writer: R, G, B, and A = 1 where the mirror is.
//
//   reflection_gl ASSET CAMERA WxH sphere|plane RADIUS NORMAL OUTPUT
//   CAMERA: x,y,z,lookx,looky,lookz,fovYDegrees (as `conus render reflection --camera`)
#define GL_GLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <cfloat>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "conus/codec/depth/glsl_interface.h"
#include "conus/codec/depth/reflection.h"
#include "conus/imageio/image_file.h"

namespace {

std::vector<double> numbers(const std::string& text) {
    std::vector<double> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');) out.push_back(std::stod(item));
    return out;
}

std::string installedFile(const std::string& name) {
    std::ifstream in(std::string(CONUS_GLSL_DIR) + "/" + name);
    if (!in) throw std::runtime_error("cannot read " + std::string(CONUS_GLSL_DIR) + "/" + name);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// An installed shader with each line `#include "x"` replaced by the installed file x (GLSL has no
// include of its own) and codec's constants after its #version line.
std::string shaderSource(const std::string& name) {
    std::stringstream in(installedFile(name));
    std::string source;
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("#include \"", 0) == 0)
            source += installedFile(line.substr(10, line.rfind('"') - 10));
        else
            source += line + "\n";
        if (line.rfind("#version", 0) == 0) source += conus::codec::glslConstants();
    }
    return source;
}

GLuint compile(GLenum stage, const std::string& source) {
    const GLuint shader = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetShaderInfoLog(shader, sizeof log, nullptr, log);
        throw std::runtime_error(std::string("shader: ") + log);
    }
    return shader;
}

// A float texture (1 or 4 channels), nearest, on texture unit `unit`.
void texture(int unit, int width, int height, int channels, const float* data) {
    GLuint id;
    glGenTextures(1, &id);
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, id);
    glTexStorage2D(GL_TEXTURE_2D, 1, channels == 1 ? GL_R32F : channels == 2 ? GL_RG32F : GL_RGBA32F, width, height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, channels == 1 ? GL_RED : channels == 2 ? GL_RG : GL_RGBA,
                    GL_FLOAT, data);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

void headlessContext() {
    auto platformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    EGLDisplay display = platformDisplay ? platformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr)
                                         : EGL_NO_DISPLAY;
    if (display == EGL_NO_DISPLAY || !eglInitialize(display, nullptr, nullptr) || !eglBindAPI(EGL_OPENGL_API))
        throw std::runtime_error("no EGL surfaceless display with desktop OpenGL");
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (context == EGL_NO_CONTEXT || !eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
        throw std::runtime_error("no OpenGL 4.5 core context without a surface");
}

void run(int argc, char** argv) {
    if (argc != 8) throw std::runtime_error("usage: reflection_gl ASSET CAMERA WxH sphere|plane RADIUS NORMAL OUTPUT");
    const std::vector<conus::codec::ReflectionFace> faces = conus::codec::readReflectionFaces(argv[1]);
    const std::vector<double> c = numbers(argv[2]);
    int width = 0, height = 0;
    if (c.size() != 7 || std::sscanf(argv[3], "%dx%d", &width, &height) != 2 || width < 1 || height < 1)
        throw std::runtime_error("bad camera or size");
    const conus::Camera camera = conus::Camera::perspective({c[0], c[1], c[2]}, {c[3], c[4], c[5]}, {0, 1, 0}, c[6],
                                                            double(width) / height, 1e-3, 1e6);
    const std::vector<double> n = numbers(argv[6]);
    const glm::vec3 normal = glm::normalize(glm::vec3(n.at(0), n.at(1), n.at(2)));
    const glm::vec3 centre(faces.front().depth.camera().eye());  // the asset's centre

    headlessContext();
    const GLuint program = glCreateProgram();
    glAttachShader(program, compile(GL_VERTEX_SHADER, shaderSource("fullscreen.vert.glsl")));
    glAttachShader(program, compile(GL_FRAGMENT_SHADER, shaderSource("reflection.frag.glsl")));
    glLinkProgram(program);
    glUseProgram(program);
    const auto at = [&](const std::string& name) { return glGetUniformLocation(program, name.c_str()); };

    // Each face: depths (unit 3k), map nodes (3k + 1), colour and coverage (3k + 2), layers side by side.
    const int layers = faces.front().layers();
    for (int k = 0; k < 6; ++k) {
        const conus::codec::ReflectionFace& face = faces[k];
        const int w = face.depth.width(), h = face.depth.height();
        std::vector<std::vector<float>> depths, colours;
        for (int l = 0; l < layers; ++l) {
            depths.push_back(conus::codec::flaggedDepths(face.layerDepth(l)));
            const conus::Image& image = face.layerImage(l);  // R, G, B, A, Z
            std::vector<float> rgba;
            for (std::size_t p = 0; p < std::size_t(w) * h; ++p)
                rgba.insert(rgba.end(), &image.pixels[p * image.channels.size()], &image.pixels[p * image.channels.size() + 4]);
            colours.push_back(std::move(rgba));
        }
        texture(3 * k, w * layers, h, 1, conus::codec::sideBySide(depths, w, h, 1).data());
        const conus::codec::SamplingMap& map = face.depth.map();
        texture(3 * k + 1, map.columns(), map.rows(), 2, glm::value_ptr(map.nodes().front()));
        texture(3 * k + 2, w * layers, h, 4, conus::codec::sideBySide(colours, w, h, 4).data());
        const std::string i = "[" + std::to_string(k) + "]", v = "uViews" + i;
        const conus::codec::DepthViewValues d = conus::codec::depthViewValues(face.depth);
        glUniformMatrix4fv(at(v + ".worldToNdc"), 1, GL_FALSE, glm::value_ptr(d.worldToNdc));
        glUniformMatrix4fv(at(v + ".ndcToWorld"), 1, GL_FALSE, glm::value_ptr(d.ndcToWorld));
        glUniform3fv(at(v + ".eye"), 1, glm::value_ptr(d.eye));
        glUniform3fv(at(v + ".forward"), 1, glm::value_ptr(d.forward));
        glUniform1f(at(v + ".near"), d.near);
        glUniform1f(at(v + ".far"), d.far);
        glUniform1i(at(v + ".perspective"), d.perspective);
        glUniform1f(at(v + ".minDepth"), d.minDepth);
        glUniform1f(at(v + ".maxDepth"), d.maxDepth);
        glUniform1i(at(v + ".solid"), d.solid);
        glUniform1f(at(v + ".jumpRelative"), d.jumpRelative);
        glUniform1f(at(v + ".jumpAbsolute"), d.jumpAbsolute);
        glUniform1i(at("uDepths" + i), 3 * k);
        glUniform1i(at("uMaps" + i), 3 * k + 1);
        glUniform1i(at("uColours" + i), 3 * k + 2);
        glUniform1f(at("uFar" + i), d.far);
    }
    // Rays a pixel a side, averaged (conus render reflection's default): the pass's scene texture
    // holds a texel a ray. Nothing is drawn behind the mirror here: it says "nothing" everywhere.
    const int samples = 3;
    std::vector<float> nothing(std::size_t(width) * samples * height * samples * 4, 0.0f);  // black, at no depth
    for (std::size_t p = 3; p < nothing.size(); p += 4) nothing[p] = FLT_MAX;
    texture(18, width * samples, height * samples, 4, nothing.data());
    glUniform1i(at("uBehind"), 18);
    glUniform1i(at("uSamples"), samples);
    glUniform1i(at("uLayers"), layers);
    const conus::codec::IntersectOptions options;  // the defaults `conus render reflection` uses
    glUniform1f(at("uStepTexels"), float(options.stepTexels));
    glUniform1i(at("uRefinements"), options.refinements);
    glUniform1i(at("uMaxSteps"), options.maxSteps);
    glUniform1f(at("uTMax"), float(options.tMax));
    // The camera's rays as affine functions of the image point (directions at camera depth 1).
    const conus::Ray r00 = camera.ray({0, 0}), r10 = camera.ray({1, 0}), r01 = camera.ray({0, 1});
    const auto along = [&](const conus::Ray& r) { return glm::vec3(r.direction / glm::dot(r.direction, camera.forward())); };
    const auto set3 = [&](const char* name, glm::vec3 value) { glUniform3fv(at(name), 1, glm::value_ptr(value)); };
    set3("uRayO0", glm::vec3(r00.origin));
    set3("uRayOU", glm::vec3(r10.origin - r00.origin));
    set3("uRayOV", glm::vec3(r01.origin - r00.origin));
    set3("uRayD0", along(r00));
    set3("uRayDU", along(r10) - along(r00));
    set3("uRayDV", along(r01) - along(r00));
    set3("uFrameEye", glm::vec3(camera.eye()));
    set3("uFrameForward", glm::vec3(camera.forward()));
    glUniform2f(at("uFrameSize"), float(width), float(height));
    glUniform1i(at("uReflectorKind"), std::string(argv[4]) == "plane" ? 1 : 0);
    set3("uReflectorCentre", centre);
    glUniform1f(at("uReflectorRadius"), std::stof(argv[5]));
    set3("uReflectorNormal", normal);
    set3("uSky", glm::vec3(conus::codec::kReflectionSky[0], conus::codec::kReflectionSky[1], conus::codec::kReflectionSky[2]));

    // One full-screen triangle into an RGBA32F target; window row 0 is the frame's top row.
    GLuint target, framebuffer, vertexArray;
    glGenTextures(1, &target);
    glActiveTexture(GL_TEXTURE19);
    glBindTexture(GL_TEXTURE_2D, target);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target, 0);
    glGenVertexArrays(1, &vertexArray);
    glBindVertexArray(vertexArray);
    glViewport(0, 0, width, height);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    std::vector<float> frame(std::size_t(width) * height * 4);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, frame.data());
    if (glGetError() != GL_NO_ERROR) throw std::runtime_error("GL error");

    conus::Image out{width, height, {"R", "G", "B", "A"}, frame};
    for (std::size_t p = 3; p < out.pixels.size(); p += 4) out.pixels[p] = out.pixels[p] >= 1.0f ? 1.0f : 0.0f;  // M: the mirror
    conus::imageio::writeImageFile(argv[7], out);
    std::printf("wrote %s: %dx%d, %d layer(s) a face\n", argv[7], width, height, layers);
}

}  // namespace

int main(int argc, char** argv) {
    try {
        run(argc, argv);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "reflection_gl: %s\n", e.what());
        return 1;
    }
}
