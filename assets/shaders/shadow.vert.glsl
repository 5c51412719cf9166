// Depth-only pass from the sun for the shadow map: same instance layout as body.vert.glsl.

layout(location = 0) in vec3 a_position;
layout(location = 2) in vec3 i_center;
layout(location = 3) in vec4 i_orientation;
layout(location = 4) in vec3 i_half_extents;

uniform mat4 u_light_view_proj;

void main() {
  vec3 world = i_center + quat_rotate(i_orientation, a_position * i_half_extents);
  gl_Position = u_light_view_proj * vec4(world, 1.0);
}
