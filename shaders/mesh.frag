#version 450 core
// Key light (warm, from the upper left, behind the camera), fill light
// (cool, from the right) and a hemisphere ambient term (sky above, ground
// below): enough shape to judge a plant. Two-sided: back faces flip their
// normal. Output in sRGB (gamma 2.2).
in vec3 vPosition;
in vec3 vNormal;
in vec3 vColor;
uniform vec3 uEye;
out vec4 fragColor;
void main() {
  vec3 n = normalize(vNormal);
  vec3 toEye = normalize(uEye - vPosition);
  if (dot(n, toEye) < 0.0) n = -n;
  vec3 albedo = pow(vColor, vec3(2.2));
  vec3 keyDir = normalize(vec3(-0.5, 0.8, 0.6));
  vec3 fillDir = normalize(vec3(0.7, 0.2, -0.4));
  float key = max(dot(n, keyDir), 0.0);
  float fill = max(dot(n, fillDir), 0.0);
  float hemi = 0.5 + 0.5 * n.y;
  vec3 ambient = mix(vec3(0.20, 0.17, 0.14), vec3(0.45, 0.50, 0.58), hemi);
  vec3 h = normalize(keyDir + toEye);
  float spec = pow(max(dot(n, h), 0.0), 32.0) * 0.08;
  vec3 c = albedo * (ambient + key * vec3(1.0, 0.95, 0.85) * 0.9 + fill * vec3(0.55, 0.62, 0.75) * 0.35) + spec;
  fragColor = vec4(pow(c, vec3(1.0 / 2.2)), 1.0);
}
