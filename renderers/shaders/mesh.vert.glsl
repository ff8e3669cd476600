#version 450 core
// A mesh vertex through the flexible pinhole camera (mesh_project.inc.glsl); the rasterizer
// connects the distorted vertices with straight edges. This is the untessellated path (identity
// or affine maps, --max-bend 0); mesh_patch.vert.glsl feeds the tessellation stages otherwise.
#include "mesh_attributes.inc.glsl"
#include "equation1.inc.glsl"
#include "mesh_project.inc.glsl"
#include "mesh_vertex.inc.glsl"

void main() {
    emitVertex(aPosition, aNormal, aColour, aUv);
}
