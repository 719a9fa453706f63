#version 450 core
in vec3 vColor;
in float vAlpha;
out vec4 fragColor;
vec3 EncodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
void main() {
  vec2 d = gl_PointCoord * 2.0 - 1.0;
  float r2 = dot(d, d);
  if (r2 > 1.0) discard;
  fragColor = vec4(EncodeSrgb(vColor), vAlpha * (1.0 - 0.5 * r2 * r2));
}
