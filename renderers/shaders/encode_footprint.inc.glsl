// The encoder's footprint rule (codec/image/encode.h), shared by both GL encoders: the filter of a
// CoNUS pixel whose footprint edges in the source are a and b (level-0 texels per CoNUS pixel).

// erf, Abramowitz and Stegun 7.1.26 (absolute error below 1.5e-7; GLSL has none built in).
float erfApprox(float x) {
    const float t = 1.0 / (1.0 + 0.3275911 * abs(x));
    const float poly = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    return sign(x) * (1.0 - poly * exp(-x * x));
}

// The unit box in CoNUS pixel units convolved with a Gaussian of standard deviation sigma along the
// unit direction major (in (s,t)), cut at +-reach; minor is the footprint's minor length in texels.
struct FootprintFilter {
    float sigma, reach, minor;
    vec2 major;
};

// The footprint's major and minor lengths and the major direction in (s,t) are the singular
// values and right singular vector of [a b]; uniformPixel is the uniform image's pixel in texels.
FootprintFilter footprintFilter(vec2 a, vec2 b, float uniformPixel) {
    const float P = dot(a, a), Q = dot(a, b), R = dot(b, b);
    const float mean = 0.5 * (P + R), spread = sqrt(0.25 * (P - R) * (P - R) + Q * Q);
    const float l1 = mean + spread, l2 = max(0.0, mean - spread);
    FootprintFilter f;
    f.minor = sqrt(l2);
    f.sigma = 0.0;
    f.major = vec2(1.0, 0.0);
    if (l1 > 0.0) {
        f.sigma = kEncodeAnisotropicSigma * max(0.0, min(1.0 - kEncodeBoxAnisotropy * sqrt(l2 / l1), 1.0 - uniformPixel / sqrt(l1)));
        const vec2 e1 = vec2(Q, l1 - P), e2 = vec2(l1 - R, Q);
        const vec2 e = dot(e1, e1) >= dot(e2, e2) ? e1 : e2;
        if (length(e) > 0.0) f.major = normalize(e);
    }
    f.reach = kEncodeGaussianReach * f.sigma;
    return f;
}
