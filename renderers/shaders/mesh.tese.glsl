#version 450 core
// A vertex of a split triangle (mesh.tesc.glsl chose the levels): its world position, normal,
// colour and uv interpolated at gl_TessCoord on the flat triangle, then through the flexible
// pinhole camera as any mesh vertex (mesh_project.inc.glsl). The position is `precise`: a vertex
// on an edge two triangles share comes out of both alike (no cracks).
layout(triangles, equal_spacing, ccw) in;
in vec3 tWorld[];
in vec3 tNormal[];
in vec3 tColour[];
in vec2 tUv[];

#include "equation1.inc.glsl"
#include "mesh_project.inc.glsl"
#include "mesh_vertex.inc.glsl"

void main() {
    const vec3 b = gl_TessCoord;
    precise vec3 world = b.x * tWorld[0] + b.y * tWorld[1] + b.z * tWorld[2];
    emitVertex(world, b.x * tNormal[0] + b.y * tNormal[1] + b.z * tNormal[2],
               b.x * tColour[0] + b.y * tColour[1] + b.z * tColour[2], b.x * tUv[0] + b.y * tUv[1] + b.z * tUv[2]);
}
