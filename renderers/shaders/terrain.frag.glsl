#version 450 core
// Lambert shading by one directional light plus ambient; the normal is interpolated per vertex.
in vec3 vColour;
in vec3 vNormal;
uniform vec3 uTowardSun;  // unit
uniform float uAmbient;
out vec4 fragColour;

void main() {
    vec3 n = normalize(vNormal);
    float diffuse = max(dot(n, uTowardSun), 0.0);
    fragColour = vec4(vColour * (uAmbient + (1.0 - uAmbient) * diffuse), 1.0);
}
