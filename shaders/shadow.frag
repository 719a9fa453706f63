#version 450 core
// Depth only. A coverage line or point (drawn wider than it is) casts a
// screen-door shadow: each texel is kept with probability equal to its
// coverage, by a fixed hash of the texel, so the filtered shadow keeps the
// twig's mean darkness and every run gives the same map.
in float vCoverage;
float Hash(vec2 p) {
  uvec2 q = uvec2(p) * uvec2(1597334677u, 3812015801u);
  uint n = (q.x ^ q.y) * 1597334677u;
  return float(n >> 8) * (1.0 / 16777216.0);
}
void main() {
  if (vCoverage < 1.0 && Hash(gl_FragCoord.xy) >= vCoverage) discard;
}
