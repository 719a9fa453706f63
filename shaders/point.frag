#version 450 core
in vec3 vColor;
out vec4 fragColor;
void main() {
  vec2 d = gl_PointCoord * 2.0 - 1.0;
  float r2 = dot(d, d);
  if (r2 > 1.0) discard;
  // A little shading so a cloud of points reads as spheres.
  fragColor = vec4(vColor * (1.0 - 0.35 * r2), 1.0);
}
