#version 450 core
// Point pipeline: particles as round sprites with a world-space diameter.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in float aSize;
layout(location = 2) in vec3 aColor;
uniform mat4 uViewProj;
uniform float uPixelsPerUnit;  // projection(1,1) * height / 2
uniform int uOrthographic;
out vec3 vColor;
void main() {
  vColor = aColor;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
  float w = uOrthographic == 1 ? 1.0 : gl_Position.w;
  gl_PointSize = max(aSize * uPixelsPerUnit / w, 1.0);
}
