#version 450 core
// Sprites (DrawList): round camera-facing discs with a world-space
// diameter, colour and alpha.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in float aSize;
layout(location = 2) in vec3 aColor;
layout(location = 3) in float aAlpha;
uniform mat4 uViewProj;
uniform float uPixelsPerUnit;  // projection(1,1) * height / 2
out vec3 vColor;
out float vAlpha;
void main() {
  vColor = aColor;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
  float pixels = aSize * uPixelsPerUnit / gl_Position.w;
  // Below a pixel the sprite keeps one pixel and its coverage goes to alpha.
  vAlpha = aAlpha * clamp(pixels * pixels, 0.0, 1.0);
  gl_PointSize = max(pixels, 1.0);
}
