// A mesh vertex as MeshRenderer uploads it (mesh_render.cpp: one interleaved buffer, position,
// normal, colour, uv at locations 0-3), read by the first vertex stage of either path: mesh.vert.glsl
// (untessellated) and mesh_patch.vert.glsl (tessellated).
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aColour;
layout(location = 3) in vec2 aUv;
