#version 450 core
// A text panel of conus-view (help, error, status bar) over the frame: one texel per window pixel,
// the overlay's top-left at uOrigin (window pixels, top row 0), straight alpha in the texture,
// written premultiplied for blending with (GL_ONE, GL_ONE_MINUS_SRC_ALPHA). Drawn with the
// full-screen triangle under a scissor rectangle; the bounds test below covers the rest.
layout(binding = 0) uniform sampler2D uOverlay;
uniform ivec2 uOrigin;
uniform int uViewportHeight;
uniform int uBottomUp;
out vec4 fragColor;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (uBottomUp != 0) p.y = uViewportHeight - 1 - p.y;
    const ivec2 t = p - uOrigin;
    if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, textureSize(uOverlay, 0)))) discard;
    const vec4 c = texelFetch(uOverlay, t, 0);
    fragColor = vec4(c.rgb * c.a, c.a);
}
