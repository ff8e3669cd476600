#version 450 core
// A mesh vertex through the flexible pinhole camera (mesh_project.inc.glsl); the rasterizer
// connects the distorted vertices with straight edges. This is the untessellated path (identity
// or affine maps, --max-bend 0); mesh_patch.vert.glsl feeds the tessellation stages otherwise.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aColour;
layout(location = 3) in vec2 aUv;

#include "equation1.inc.glsl"
#include "mesh_project.inc.glsl"
#include "mesh_vertex.inc.glsl"

void main() {
    emitVertex(aPosition, aNormal, aColour, aUv);
}
