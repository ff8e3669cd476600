#version 450 core
// Resolves a multisampled mesh render: colour (and coverage, alpha) is the mean of the samples, as
// the reference averages its sub-pixel rays; camera depth is the nearest sample's (the minimum),
// never a mean, which across a silhouette would invent a depth between the two surfaces.
uniform sampler2DMS uColour;
uniform sampler2DMS uDepth;
uniform int uSamples;
layout(location = 0) out vec4 oColour;
layout(location = 1) out float oDepth;

void main() {
    const ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 sum = vec4(0.0);
    float nearest = texelFetch(uDepth, p, 0).r;
    for (int s = 0; s < uSamples; ++s) {
        sum += texelFetch(uColour, p, s);
        nearest = min(nearest, texelFetch(uDepth, p, s).r);
    }
    oColour = sum / float(uSamples);
    oDepth = nearest;
}
