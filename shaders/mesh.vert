#version 450 core
// Mesh pipeline: world-space positions and normals, colour per vertex.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aColor;
layout(location = 3) in float aCoverage;  // sub-pixel coverage in (0, 1]; 1 when absent
uniform mat4 uViewProj;
out vec3 vPosition;
out vec3 vNormal;
out vec3 vColor;
out float vCoverage;
void main() {
  vPosition = aPosition;
  vNormal = aNormal;
  vColor = aColor;
  vCoverage = aCoverage;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
}
