// The last vertex stage of a mesh (mesh.vert.glsl, or mesh.tese.glsl when the triangles are
// split): what mesh.frag.glsl receives, and the vertex through the flexible pinhole camera. Needs
// equation1.inc.glsl and mesh_project.inc.glsl.
uniform vec4 uDepthRow;  // camera depth = dot(uDepthRow, (p, 1)): worldToCamera's z row
out vec3 vWorld;
out vec3 vNormal;
out vec3 vColour;
out vec2 vUv;
out float vDepth;

void emitVertex(vec3 world, vec3 normal, vec3 colour, vec2 uv) {
    vWorld = world;
    vNormal = normal;
    vColour = colour;
    vUv = uv;
    vDepth = dot(uDepthRow, vec4(world, 1.0));
    gl_Position = fpcClipPosition(world);
}
