#version 450 core
// Scene pipeline (DrawList): one mesh drawn once per instance; the model
// matrix and a tint come per instance.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aColor;
layout(location = 3) in mat4 aModel;  // locations 3..6
layout(location = 7) in vec3 aTint;
layout(location = 8) in float aCoverage;  // sub-pixel coverage in (0, 1]; 1 when absent
uniform mat4 uViewProj;
out vec3 vPosition;
out vec3 vNormal;
out vec3 vColor;
out float vCoverage;
void main() {
  vCoverage = aCoverage;
  vec4 world = aModel * vec4(aPosition, 1.0);
  vPosition = world.xyz;
  vNormal = mat3(aModel) * aNormal;  // rotation and uniform scale
  vColor = aColor * aTint;
  gl_Position = uViewProj * world;
}
