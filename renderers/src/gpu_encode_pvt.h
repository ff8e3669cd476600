// Private: what the two GL encoders share (gpu_encode.cpp: the EWA encoder and the dispatch;
// gpu_encode_mip.cpp: the mipmapped encoder).
#pragma once

#include <glad/gl.h>

#include "conus/renderers/gpu_image.h"
#include "gl_objects_pvt.h"
#include "gpu_encode_plan_pvt.h"

namespace conus::renderers {

// The mesh's vertices (distorted position, undistorted position, footprint) and triangles into
// the vertex array's buffers, for encode.vert.glsl.
void uploadMesh(const GladGLContext& gl, const Mesh& mesh, GLuint vertexArray, GLuint vertexBuffer, GLuint indexBuffer);

// Clears the bound framebuffer and draws all of the mesh's triangles from the bound vertex array
// and program, waits for the GPU, and adds the time since `start` to t.drawMs.
void drawMeshTimed(const GladGLContext& gl, const Mesh& mesh, GpuTimings& t, Clock::time_point& start);

// The mipmapped encoder (gpu_image.h) into `out` (the output's size and channels), timed into t
// from `start`.
void encodeMipmapped(Context& context, const Image& source, const codec::SamplingMap& map, const codec::EncodeOptions& options,
                     const GpuEncodeOptions& gpu, Image& out, GpuTimings& t, Clock::time_point& start);

}  // namespace conus::renderers
