// `--backend auto|egl|osmesa|cpu` for every command that renders. auto takes the fastest that
// works: a hardware GL device when there is one, else the CPU reference (on Mesa's software
// rasterizer the CPU path measures several times faster, bench/README.md).
#pragma once

#include <memory>
#include <string>

#include "conus/codec/decode.h"
#include "conus/codec/encode.h"
#include "conus/renderers/context.h"

namespace CLI {
class App;
}

namespace conus::cli {

class Renderer {
public:
    explicit Renderer(const std::string& backendName);
    format::Image encode(const format::Image& source, const codec::SamplingMap& map, const codec::EncodeOptions& options);
    format::Image decode(const format::Image& conus, const codec::SamplingMap& map, const codec::DecodeOptions& options);
    // "cpu", or "egl: <GL_RENDERER>" / "osmesa: <GL_RENDERER>".
    std::string describe() const;

private:
    std::unique_ptr<gl::Context> m_context;  // null: the CPU reference
};

void addBackendOption(CLI::App& command, std::string& backend);

}  // namespace conus::cli
