// Shared vertex-stage helper (prepended to body.vert.glsl and shadow.vert.glsl).

// Rotates v by the unit quaternion q stored as (x, y, z, w): v' = q v q*.
vec3 quat_rotate(vec4 q, vec3 v) {
  vec3 t = 2.0 * cross(q.xyz, v);
  return v + q.w * t + cross(q.xyz, t);
}
