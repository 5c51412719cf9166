// Line segments as screen-aligned quads of width i_width (pixels), one instance per segment.
// a_corner = (end, side): end 0 at i_a, 1 at i_b; side -1 or +1 across the segment. The segment
// is clipped to the near plane in view space first so that it never flips behind the camera;
// the ends are extended by half the width for square caps.

layout(location = 0) in vec2 a_corner;
layout(location = 1) in vec3 i_a;
layout(location = 2) in vec3 i_b;
layout(location = 3) in vec3 i_color;
layout(location = 4) in float i_width;

uniform mat4 u_view;
uniform mat4 u_proj;
uniform vec2 u_viewport;    // pixels
uniform float u_near;       // m

flat out vec3 v_color;

void main() {
  v_color = i_color;
  vec4 a = u_view * vec4(i_a, 1.0);
  vec4 b = u_view * vec4(i_b, 1.0);
  float zn = -1.001 * u_near;
  if (a.z > zn && b.z > zn) {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // wholly behind the near plane: clipped away
    return;
  }
  if (a.z > zn) a = mix(a, b, (zn - a.z) / (b.z - a.z));
  if (b.z > zn) b = mix(b, a, (zn - b.z) / (a.z - b.z));
  vec4 ca = u_proj * a;
  vec4 cb = u_proj * b;
  vec2 half_vp = 0.5 * u_viewport;
  vec2 sa = ca.xy / ca.w * half_vp;
  vec2 sb = cb.xy / cb.w * half_vp;
  vec2 dir = sb - sa;
  float len = length(dir);
  dir = len > 1e-4 ? dir / len : vec2(1.0, 0.0);
  vec2 perp = vec2(-dir.y, dir.x);
  float hw = 0.5 * i_width;
  vec4 c = a_corner.x < 0.5 ? ca : cb;
  vec2 offset_px = perp * (a_corner.y * hw) + dir * (a_corner.x < 0.5 ? -hw : hw);
  c.xy += offset_px / half_vp * c.w;
  gl_Position = c;
}
