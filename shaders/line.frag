#version 450 core
// Colours arrive linear (mesh/color.h); output is sRGB-encoded.
in vec3 vColor;
out vec4 fragColor;
vec3 EncodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
void main() { fragColor = vec4(EncodeSrgb(vColor), 1.0); }
