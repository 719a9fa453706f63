#version 450 core
// Scene lighting: up to 8 lights from the DrawList (sun: directional, with
// the first sun casting shadows; ambient: a hemisphere term, brighter from
// above; point: inverse-square falloff). Two-sided. Colours arrive linear;
// output is sRGB-encoded.
in vec3 vPosition;
in vec3 vNormal;
in vec3 vColor;
in float vCoverage;  // alpha: the covered fraction of a coverage line or point
uniform vec3 uEye;
uniform int uLightCount;
uniform int uLightType[8];        // 0 sun, 1 ambient, 2 point
uniform vec3 uLightVector[8];     // sun: toward the light; point: position
uniform vec3 uLightColor[8];      // colour * intensity, linear
uniform int uShadowLight;         // index of the shadow-casting sun, -1: none
uniform mat4 uLightViewProj;
uniform sampler2DShadow uShadow;
uniform int uWire;                // 1: the wireframe overlay pass, flat dark lines
out vec4 fragColor;

vec3 EncodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

float Visibility(vec3 n) {
  vec4 q = uLightViewProj * vec4(vPosition + n * 0.01, 1.0);
  vec3 c = q.xyz / q.w * 0.5 + 0.5;
  if (c.x <= 0.0 || c.x >= 1.0 || c.y <= 0.0 || c.y >= 1.0 || c.z >= 1.0) return 1.0;
  vec2 texel = 1.0 / vec2(textureSize(uShadow, 0));
  float sum = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x)
      sum += texture(uShadow, vec3(c.xy + vec2(x, y) * texel, c.z - 0.001));
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
  // The shadow lookup once, outside the loop: llvmpipe runs both sides of
  // a branch, so a lookup inside it costs every light.
  float visibility = uShadowLight >= 0 ? Visibility(n) : 1.0;
  vec3 light = vec3(0.0);
  float spec = 0.0;
  for (int i = 0; i < uLightCount; ++i) {
    if (uLightType[i] == 1) {
      light += uLightColor[i] * (0.55 + 0.45 * n.y);
      continue;
    }
    vec3 l;
    vec3 c = uLightColor[i];
    if (uLightType[i] == 0) {
      l = normalize(uLightVector[i]);
      if (i == uShadowLight) c *= visibility;
    } else {
      vec3 d = uLightVector[i] - vPosition;
      float d2 = max(dot(d, d), 1e-4);
      l = d * inversesqrt(d2);
      c /= d2;
    }
    float diffuse = max(dot(n, l), 0.0);
    light += c * diffuse;
    spec += pow(max(dot(n, normalize(l + toEye)), 0.0), 32.0) * 0.04 * diffuse * length(c);
  }
  fragColor = vec4(EncodeSrgb(vColor * light + spec), vCoverage);
}
