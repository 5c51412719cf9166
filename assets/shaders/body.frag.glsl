// Boxes (u_kind 0): lit faces with a thin darker outline along the edges, about 1.5 px wide
// whatever the distance. Spheres (u_kind 1): a two-tone octant pattern in the body frame (like a
// beach ball) so that spin about any axis is visible.

in vec3 v_world;
in vec3 v_normal;
in vec3 v_local;
flat in vec3 v_half_extents;
flat in vec3 v_color;
flat in float v_alpha;

uniform int u_kind;

out vec4 o_color;

void main() {
  vec3 n = normalize(v_normal);
  vec3 albedo = v_color;
  if (u_kind == 0) {
    // Distance (m) to the six face planes; on a face one of them is ~0 and the distance to the
    // face's border is the middle one.
    vec3 d = max(v_half_extents - abs(v_local), vec3(0.0));
    float lo = min(d.x, min(d.y, d.z));
    float hi = max(d.x, max(d.y, d.z));
    float edge = d.x + d.y + d.z - lo - hi;
    float px = edge / max(fwidth(edge), 1e-6);
    albedo *= mix(0.5, 1.0, smoothstep(0.25, 1.75, px));
  } else {
    vec3 u = v_local / v_half_extents;
    vec3 s = clamp(u / max(fwidth(u), vec3(1e-5)), -1.0, 1.0);  // antialiased sign
    albedo *= mix(0.68, 1.0, 0.5 + 0.5 * s.x * s.y * s.z);
  }
  o_color = finish(shade(albedo, n, v_world, 48.0, 0.12), v_world, v_alpha);
}
