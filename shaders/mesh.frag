#version 450 core
// Key light (warm, from the upper left, casting shadows), fill light
// (cool, from the right) and a hemisphere ambient term (sky above, ground
// below): enough shape to judge a plant. Two-sided: back faces flip their
// normal. Colours arrive linear (mesh/color.h); output is sRGB-encoded.
in vec3 vPosition;
in vec3 vNormal;
in vec3 vColor;
in float vCoverage;  // alpha: the fraction of a coverage line or point that is covered
uniform vec3 uEye;
uniform vec3 uKeyDir;             // toward the key light
uniform mat4 uLightViewProj;
uniform sampler2DShadow uShadow;  // depth from the key light
uniform int uShadows;
uniform int uWire;                // 1: a wireframe overlay pass, flat dark lines
out vec4 fragColor;

// The exact sRGB transfer function (IEC 61966-2-1).
vec3 EncodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

// 3x3 percentage-closer filtering of the key light's shadow map.
float KeyVisibility(vec3 n) {
  if (uShadows == 0) return 1.0;
  vec4 q = uLightViewProj * vec4(vPosition + n * 0.002, 1.0);
  vec3 c = q.xyz / q.w * 0.5 + 0.5;
  if (c.x <= 0.0 || c.x >= 1.0 || c.y <= 0.0 || c.y >= 1.0 || c.z >= 1.0) return 1.0;
  vec2 texel = 1.0 / vec2(textureSize(uShadow, 0));
  float sum = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x)
      sum += texture(uShadow, vec3(c.xy + vec2(x, y) * texel, c.z - 0.0015));
  return sum / 9.0;
}
void main() {
  if (uWire == 1) {
    fragColor = vec4(0.08, 0.08, 0.10, 1.0);
    return;
  }
  vec3 n = normalize(vNormal);
  vec3 toEye = normalize(uEye - vPosition);
  if (dot(n, toEye) < 0.0) n = -n;
  vec3 albedo = vColor;
  vec3 keyDir = normalize(uKeyDir);
  vec3 fillDir = normalize(vec3(0.7, 0.2, -0.4));
  float key = max(dot(n, keyDir), 0.0) * KeyVisibility(n);
  float fill = max(dot(n, fillDir), 0.0);
  float hemi = 0.5 + 0.5 * n.y;
  vec3 ambient = mix(vec3(0.20, 0.17, 0.14), vec3(0.45, 0.50, 0.58), hemi);
  vec3 h = normalize(keyDir + toEye);
  float spec = pow(max(dot(n, h), 0.0), 32.0) * 0.08;
  vec3 c = albedo * (ambient + key * vec3(1.0, 0.95, 0.85) * 0.9 + fill * vec3(0.55, 0.62, 0.75) * 0.35) + spec;
  fragColor = vec4(EncodeSrgb(c), vCoverage);
}
