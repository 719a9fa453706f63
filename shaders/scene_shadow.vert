#version 450 core
// Shadow pass of the scene pipeline: depth from the sun, per instance.
layout(location = 0) in vec3 aPosition;
layout(location = 3) in mat4 aModel;
uniform mat4 uLightViewProj;
out float vCoverage;  // shadow.frag's screen door: always opaque here
void main() {
  vCoverage = 1.0;
  gl_Position = uLightViewProj * aModel * vec4(aPosition, 1.0);
}
