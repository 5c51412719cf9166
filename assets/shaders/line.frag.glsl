// Unlit line colour (linear RGB), gamma encoded like the lit surfaces.

flat in vec3 v_color;

out vec4 o_color;

void main() {
  o_color = vec4(pow(clamp(v_color, 0.0, 1.0), vec3(1.0 / 2.2)), 1.0);
}
