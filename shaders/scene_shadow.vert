#version 450 core
// Shadow pass of the scene pipeline: depth from the sun, per instance.
layout(location = 0) in vec3 aPosition;
layout(location = 3) in mat4 aModel;
uniform mat4 uLightViewProj;
layout(location = 8) in float aCoverage;  // sub-pixel coverage in (0, 1]; 1 when absent
out float vCoverage;  // shadow.frag's screen door
void main() {
  vCoverage = aCoverage;
  gl_Position = uLightViewProj * aModel * vec4(aPosition, 1.0);
}
