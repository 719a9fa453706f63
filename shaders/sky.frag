#version 450 core
// Sky gradient by the elevation of the view ray: the horizon colour at 0
// degrees (and below), the top colour at the zenith.
in vec2 vNdc;
uniform mat4 uInverseViewProj;
uniform vec3 uTop;      // linear
uniform vec3 uHorizon;  // linear
out vec4 fragColor;
vec3 EncodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
void main() {
  vec4 a = uInverseViewProj * vec4(vNdc, -1.0, 1.0);
  vec4 b = uInverseViewProj * vec4(vNdc, 1.0, 1.0);
  vec3 dir = normalize(b.xyz / b.w - a.xyz / a.w);
  float t = clamp(dir.y, 0.0, 1.0);
  fragColor = vec4(EncodeSrgb(mix(uHorizon, uTop, pow(t, 0.5))), 1.0);
}
