#version 450 core
// A mesh vertex handed to the tessellation stages as it is (mesh.tesc.glsl chooses how finely to
// split its triangle, mesh.tese.glsl projects the vertices it makes).
#include "mesh_attributes.inc.glsl"
out vec3 pWorld;
out vec3 pNormal;
out vec3 pColour;
out vec2 pUv;

void main() {
    pWorld = aPosition;
    pNormal = aNormal;
    pColour = aColour;
    pUv = aUv;
}
