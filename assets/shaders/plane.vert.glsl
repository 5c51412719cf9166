// One plane as a square of side 2 * u_half_size (m) drawn as a 4-vertex triangle strip without
// vertex buffers: corner i is (+-1, +-1) in the plane basis (u_t1, u_t2) around u_origin.

uniform mat4 u_view_proj;
uniform vec3 u_origin;      // point of the plane nearest the centre hint (m)
uniform vec3 u_t1;          // unit tangents, u_t1 x u_t2 = plane normal
uniform vec3 u_t2;
uniform float u_half_size;  // m

out vec3 v_world;
out vec2 v_square;          // position in the square, [-1, 1]^2

void main() {
  vec2 c = vec2((gl_VertexID & 1) == 0 ? -1.0 : 1.0, (gl_VertexID & 2) == 0 ? -1.0 : 1.0);
  v_square = c;
  v_world = u_origin + u_half_size * (c.x * u_t1 + c.y * u_t2);
  gl_Position = u_view_proj * vec4(v_world, 1.0);
}
