#version 450 core
// Shadow pass: depth from the key light.
layout(location = 0) in vec3 aPosition;
layout(location = 3) in float aCoverage;  // sub-pixel coverage in (0, 1]; 1 when absent
uniform mat4 uLightViewProj;
out float vCoverage;
void main() {
  vCoverage = aCoverage;
  gl_Position = uLightViewProj * vec4(aPosition, 1.0);
}
