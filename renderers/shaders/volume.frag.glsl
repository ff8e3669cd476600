#version 450 core
// CoNUS volume ray casting, one fragment per CoNUS pixel: the GLSL twin of codec's
// castVolumeRay (codec/volume/raycast.h states the sampling both follow).
uniform sampler3D uVolume;        // R32F samples, GL_LINEAR, clamped
uniform sampler1D uTransfer;      // the transfer function's table, RGBA32F, GL_LINEAR
uniform sampler2D uUndistorted;   // RG32F undistorted position per pixel (unused when uIdentity)
uniform bool uIdentity;
uniform vec2 uOutputSize;
uniform mat4 uNdcToWorld;         // inverse of the camera's world-to-NDC (column vectors)
uniform vec3 uForward;
uniform float uNear, uFar;
uniform vec3 uExtent, uSpacing;
uniform float uStep, uStepVoxels;
uniform bool uJitter;
uniform float uRangeLo, uRangeScale;
uniform float uDepthOpacity;

layout(location = 0) out vec4 oColour;
layout(location = 1) out float oDepth;

// codec::pixelJitter: the same 32-bit hash, bit for bit.
float pixelJitter(ivec2 p) {
    uint h = uint(p.x) * 0x8da6b343u ^ uint(p.y) * 0xd8163841u;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return float(h >> 8) * (1.0 / 16777216.0);
}

vec3 unprojectNdc(vec2 uv, float z) {
    const vec4 p = uNdcToWorld * vec4(uv, z, 1.0);
    return p.xyz / p.w;
}

void main() {
    const ivec2 pixel = ivec2(gl_FragCoord.xy);
    const vec2 uv = uIdentity ? gl_FragCoord.xy / uOutputSize : texelFetch(uUndistorted, pixel, 0).xy;
    oColour = vec4(0.0);
    oDepth = uFar;

    // The camera's ray through uv: along the line between the near and far planes, from depth 0.
    const vec3 pNear = unprojectNdc(uv, 0.0), pFar = unprojectNdc(uv, 1.0);
    const vec3 direction = normalize(pFar - pNear);
    const float cosine = dot(direction, uForward);
    if (!(cosine > 0.0)) return;
    const vec3 origin = pNear - direction * (uNear / cosine);

    float tEnter = uNear / cosine, tExit = uFar / cosine;
    for (int a = 0; a < 3; ++a) {
        if (direction[a] == 0.0) {
            if (origin[a] < 0.0 || origin[a] > uExtent[a]) return;
            continue;
        }
        const float inv = 1.0 / direction[a];
        float t0 = -origin[a] * inv, t1 = (uExtent[a] - origin[a]) * inv;
        if (t0 > t1) { const float s = t0; t0 = t1; t1 = s; }
        tEnter = max(tEnter, t0);
        tExit = min(tExit, t1);
    }
    if (!(tEnter < tExit)) return;

    const vec3 size = vec3(textureSize(uVolume, 0));
    const float offset = uJitter ? pixelJitter(pixel) : 0.5;
    vec3 colour = vec3(0.0);
    float alpha = 0.0;
    bool depthSet = false;
    for (int k = 0;; ++k) {
        const float t = tEnter + (float(k) + offset) * uStep;
        if (t > tExit) break;
        const vec3 g = clamp((origin + t * direction) / uSpacing, vec3(0.0), size - 1.0);
        const float value = texture(uVolume, (g + 0.5) / size).r;
        const float s = clamp((value - uRangeLo) * uRangeScale, 0.0, 1.0);
        const vec4 c = texture(uTransfer, (s * float(kTransferTableSize - 1) + 0.5) / float(kTransferTableSize));
        const float a = 1.0 - pow(1.0 - c.a, uStepVoxels);
        colour += (1.0 - alpha) * a * c.rgb;
        alpha += (1.0 - alpha) * a;
        if (!depthSet && alpha >= uDepthOpacity) {
            oDepth = t * cosine;
            depthSet = true;
        }
        if (alpha >= kTerminationOpacity) break;
    }
    oColour = vec4(colour, alpha);
}
