// Checkered plane: squares of side u_checker (m) in the plane basis, anchored at the world
// origin, box-filtered over the pixel footprint so that they fade to the mean colour far away
// instead of aliasing. Lit from either side, receives shadows; an opaque plane fades into the
// background near the border of its square. Alpha below 1 is blended by the caller.
//
// Planes bound half-spaces (the normal points to the free side), so the part of a plane that lies
// inside another plane's solid side can never be seen in the simulated world: it is discarded.
// Four tilted walls thus show as a clean funnel instead of four crossing squares.

in vec3 v_world;
in vec2 v_square;

uniform vec3 u_normal;      // unit normal of the free side
uniform vec3 u_t1;
uniform vec3 u_t2;
uniform float u_checker;    // m
uniform vec3 u_color_a;     // linear RGB
uniform vec3 u_color_b;
uniform float u_alpha;
uniform int u_clip_count;   // number of other planes in u_clip
uniform vec4 u_clip[16];    // other planes: unit normal (xyz) and offset (w, m)

out vec4 o_color;

// Integral from 0 to x of the square wave that is +1 on [0, 1) and -1 on [1, 2), period 2.
vec2 square_wave_integral(vec2 x) {
  vec2 f = mod(x, 2.0);
  return 1.0 - abs(f - 1.0);
}

void main() {
  for (int i = 0; i < u_clip_count; ++i) {
    if (dot(u_clip[i].xyz, v_world) < u_clip[i].w - 1e-4) discard;
  }
  vec2 uv = vec2(dot(v_world, u_t1), dot(v_world, u_t2)) / u_checker;
  vec2 w = max(fwidth(uv), vec2(1e-4));
  // Mean of the square wave over the pixel footprint [uv - w/2, uv + w/2], per axis.
  vec2 mean = (square_wave_integral(uv + 0.5 * w) - square_wave_integral(uv - 0.5 * w)) / w;
  float t = 0.5 - 0.5 * mean.x * mean.y;
  vec3 albedo = mix(u_color_a, u_color_b, t);

  vec3 n = gl_FrontFacing ? u_normal : -u_normal;
  vec3 c = shade(albedo, n, v_world, 32.0, 0.04);
  float border = smoothstep(0.75, 1.0, max(abs(v_square.x), abs(v_square.y)));
  vec4 o = finish(c, v_world, u_alpha);
  if (u_alpha >= 1.0) o.rgb = mix(o.rgb, pow(u_background, vec3(1.0 / 2.2)), border);
  o_color = o;
}
