// Boxes and spheres: a unit mesh (cube [-1,1]^3 or unit sphere) instanced once per body.
// Per instance: centre (m), orientation (unit quaternion x, y, z, w), half extents (m; the radius
// three times for a sphere), linear RGB colour and opacity (1: opaque; below 1: a ghost).

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 i_center;
layout(location = 3) in vec4 i_orientation;
layout(location = 4) in vec3 i_half_extents;
layout(location = 5) in vec4 i_color;

uniform mat4 u_view_proj;

out vec3 v_world;                // world position (m)
out vec3 v_normal;               // world normal
out vec3 v_local;                // body-frame position (m)
flat out vec3 v_half_extents;    // m
flat out vec3 v_color;
flat out float v_alpha;

void main() {
  vec3 local = a_position * i_half_extents;
  v_world = i_center + quat_rotate(i_orientation, local);
  v_normal = quat_rotate(i_orientation, a_normal);
  v_local = local;
  v_half_extents = i_half_extents;
  v_color = i_color.rgb;
  v_alpha = i_color.a;
  gl_Position = u_view_proj * vec4(v_world, 1.0);
}
