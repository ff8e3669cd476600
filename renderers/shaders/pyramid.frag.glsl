#version 450 core
// One level of the encoder's source pyramid from the level above it: an exact area average
// (each output texel the overlap-weighted mean of the up to 3 x 3 source texels it covers), at the
// CPU reference's sizes ((w + 1) / 2), which GL's own mipmaps (w / 2, filtered by a blit) do not
// reproduce for odd sizes. Levels live side by side in one atlas texture.
layout(location = 0) out vec4 fragColor;
uniform sampler2D uSource;
uniform ivec4 uSourceRect;  // x, y offset in uSource; width, height of the level read
uniform ivec4 uTargetRect;  // the same for the level written

// Source texels [first, first + count) covered by target texel i, with their weights.
int axisWeights(int i, int source, int target, out int first, out float weights[4]) {
    const float scale = float(source) / float(target);
    const float lo = float(i) * scale, hi = float(i + 1) * scale;
    first = min(source - 1, int(floor(lo)));
    const int last = min(source, int(ceil(hi)));
    int count = 0;
    for (int k = first; k < last && count < 4; ++k) {
        const float overlap = min(hi, float(k + 1)) - max(lo, float(k));
        if (overlap > 0.0) weights[count++] = overlap / scale;
        else if (count == 0) ++first;  // a zero-width sliver at the start
    }
    return count;
}

void main() {
    const ivec2 t = ivec2(gl_FragCoord.xy) - uTargetRect.xy;
    int fx, fy;
    float wx[4], wy[4];
    const int nx = axisWeights(t.x, uSourceRect.z, uTargetRect.z, fx, wx);
    const int ny = axisWeights(t.y, uSourceRect.w, uTargetRect.w, fy, wy);
    vec4 sum = vec4(0.0);
    for (int j = 0; j < ny; ++j) {
        vec4 row = vec4(0.0);
        for (int i = 0; i < nx; ++i) row += wx[i] * texelFetch(uSource, uSourceRect.xy + ivec2(fx + i, fy + j), 0);
        sum += wy[j] * row;
    }
    fragColor = sum;
}
