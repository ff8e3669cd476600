#include "backend.h"

#include <CLI/CLI.hpp>

#include "conus/renderers/gpu_image.h"

namespace conus::cli {
namespace {

bool isSoftwareRasterizer(const std::string& renderer) {
    return renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos ||
           renderer.find("swrast") != std::string::npos;
}

}  // namespace

Renderer::Renderer(const std::string& backendName) {
    const gl::Backend backend = gl::parseBackend(backendName);
    if (backend == gl::Backend::Cpu) return;
    if (backend != gl::Backend::Auto) {
        m_context = gl::Context::create(backend);  // asked for by name: its failure is an error
        return;
    }
    try {
        auto context = gl::Context::create(gl::Backend::Auto);
        if (!isSoftwareRasterizer(context->renderer())) m_context = std::move(context);
    } catch (const Error&) {
        // No GL at all: the CPU reference serves.
    }
}

format::Image Renderer::encode(const format::Image& source, const codec::SamplingMap& map,
                               const codec::EncodeOptions& options) {
    if (!m_context) return codec::encodeImage(source, map, options);
    return gl::encodeImageGpu(*m_context, source, map, options);
}

format::Image Renderer::decode(const format::Image& conus, const codec::SamplingMap& map,
                               const codec::DecodeOptions& options) {
    if (!m_context) return codec::decodeImage(conus, map, options);
    codec::checkDecodeMemory(conus, options.width, options.height);
    return gl::decodeImageGpu(*m_context, conus, map, options);
}

std::string Renderer::describe() const {
    if (!m_context) return "cpu";
    return gl::backendName(m_context->backend()) + ": " + m_context->renderer();
}

void addBackendOption(CLI::App& command, std::string& backend) {
    command.add_option("--backend", backend,
                       "auto (default: a GPU when there is one, else the CPU) | egl | osmesa | cpu")
        ->default_val("auto")
        ->check(CLI::IsMember({"auto", "egl", "osmesa", "cpu"}, CLI::ignore_case));
}

}  // namespace conus::cli
