#version 450 core
// codec/mesh/shading.h's shading, its constants injected: albedo (vertex colour, else the texture
// at uv, else grey) lit by a two-sided headlight; camera depth into the second target. Peeling
// (uPeel) keeps only the fragments behind the previous layer's depth at their pixel.
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
uniform bool uPeel;           // depth peeling: only what lies behind the previous layer
uniform sampler2D uBehind;    // the previous layer's camera depth, one a pixel
uniform float uPeelGap;       // codec::kPeelGap: a surface counts more than this much of its depth behind
layout(location = 0) out vec4 oColour;
layout(location = 1) out float oDepth;

void main() {
    if (uPeel && !(vDepth > texelFetch(uBehind, ivec2(gl_FragCoord.xy), 0).r * (1.0 + uPeelGap))) discard;
    const vec3 albedo = uAlbedo == 0 ? vColour : uAlbedo == 1 ? texture(uTexture, vUv).rgb : vec3(kMeshGrey);
    const vec3 toLight = uPerspective ? normalize(uEye - vWorld) : -uForward;
    const float lit = kMeshAmbient + (1.0 - kMeshAmbient) * abs(dot(normalize(vNormal), toLight));
    oColour = vec4(albedo * lit, 1.0);
    oDepth = vDepth;
}
