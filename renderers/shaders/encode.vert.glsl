#version 450 core
// The mesh of distorted map nodes (paper section 3.2): position = SM(p) in normalized image
// coordinates, texture coordinate = the undistorted p, and the pixel's footprint there. GL's window y is the image's row index
// (images travel to and from GL top row first), so v maps to NDC y without a flip.
layout(location = 0) in vec2 aDistorted;
layout(location = 1) in vec2 aUndistorted;
layout(location = 2) in vec4 aFootprint;  // codec::FootprintField per CoNUS pixel: xy along x, zw along y
out vec2 vUndistorted;
out vec4 vFootprint;

void main() {
    vUndistorted = aUndistorted;
    vFootprint = aFootprint;
    gl_Position = vec4(aDistorted * 2.0 - 1.0, 0.0, 1.0);
}
