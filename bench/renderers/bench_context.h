// The GL context of the renderer benchmarks (one binary, renderers_bench): the backend that
// CONUS_BACKEND names (auto, egl, osmesa; default auto: the EGL hardware device on a GPU machine,
// llvmpipe elsewhere).
#pragma once

#include <cstdlib>
#include <memory>

#include "conus/core/error.h"
#include "conus/renderers/context.h"

namespace conus::bench {

// A new context on that backend; throws conus::Error when it cannot start.
inline std::unique_ptr<renderers::Context> createBenchContext() {
    const char* backend = std::getenv("CONUS_BACKEND");
    return renderers::Context::create(backend ? parseEnum<renderers::Backend>(backend) : renderers::Backend::Auto);
}

// One context shared by the GPU rows that can skip, made on first use; null when no backend
// works (those rows then skip with "no GL backend").
inline renderers::Context* sharedBenchContext() {
    static const std::unique_ptr<renderers::Context> context = []() -> std::unique_ptr<renderers::Context> {
        try {
            return createBenchContext();
        } catch (const Error&) {
            return nullptr;
        }
    }();
    return context.get();
}

}  // namespace conus::bench
