#version 450 core
// codec/mesh/shading.h's shading, its constants injected: albedo (vertex colour, else the texture
// at uv, else grey) lit by a two-sided headlight; camera depth into the second target.
in vec3 vWorld;
in vec3 vNormal;
in vec3 vColour;
in vec2 vUv;
in float vDepth;
uniform int uAlbedo;          // 0: vertex colour, 1: texture, 2: kMeshGrey
uniform sampler2D uTexture;   // base colour, row 0 the top (uv (0,0) top-left)
uniform bool uPerspective;
uniform vec3 uEye;            // perspective: the centre of projection
uniform vec3 uForward;        // orthographic: the unit viewing direction
layout(location = 0) out vec4 oColour;
layout(location = 1) out float oDepth;

void main() {
    const vec3 albedo = uAlbedo == 0 ? vColour : uAlbedo == 1 ? texture(uTexture, vUv).rgb : vec3(kMeshGrey);
    const vec3 toLight = uPerspective ? normalize(uEye - vWorld) : -uForward;
    const float lit = kMeshAmbient + (1.0 - kMeshAmbient) * abs(dot(normalize(vNormal), toLight));
    oColour = vec4(albedo * lit, 1.0);
    oDepth = vDepth;
}
