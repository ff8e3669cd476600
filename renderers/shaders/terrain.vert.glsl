#version 450 core
// Height-field mesh in world space (metres; x right, y up, z toward the viewer).
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aColour;
layout(location = 2) in vec3 aNormal;
uniform mat4 uViewProjection;
out vec3 vColour;
out vec3 vNormal;

void main() {
    vColour = aColour;
    vNormal = aNormal;
    gl_Position = uViewProjection * vec4(aPosition, 1.0);
}
