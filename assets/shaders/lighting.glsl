// Shared fragment-stage lighting (prepended to body.frag.glsl and plane.frag.glsl).
//
// Lighting is done in linear RGB: hemisphere ambient (sky above, ground bounce below), a weak
// fill light from the camera's right, the sun (Lambert diffuse + mild Blinn-Phong specular)
// attenuated by the shadow map, then fog toward the background and a 1/2.2 gamma encoding.
//
// Shadows: shadow mapping (Williams 1978, "Casting curved shadows on curved surfaces") with
// percentage-closer filtering (Reeves, Salesin & Cook 1987) as taught by LearnOpenGL's "Shadow
// Mapping": a 3x3 grid of hardware-compared (bilinear) taps, plus a normal offset along the
// surface normal against shadow acne.

uniform vec3 u_light_dir;           // unit direction the sunlight travels
uniform vec3 u_eye;                 // camera position (m)
uniform vec3 u_fill_dir;            // unit direction toward the fill light
uniform vec3 u_background;          // background colour, linear RGB
uniform vec2 u_fog;                 // fog start and end distance from the eye (m)
uniform int u_shadow_enabled;       // 0: no shadow map this frame
uniform sampler2DShadow u_shadow_map;
uniform mat4 u_light_view_proj;     // world -> sun clip space
uniform float u_shadow_offset;      // normal offset (m), about 1.5 shadow texels
uniform float u_shadow_texel;       // 1 / shadow map size

float sun_visibility(vec3 p, vec3 n) {
  if (u_shadow_enabled == 0) return 1.0;
  float cos_l = clamp(dot(n, -u_light_dir), 0.0, 1.0);
  float sin_l = sqrt(1.0 - cos_l * cos_l);
  vec3 q = p + n * u_shadow_offset * (0.5 + 1.5 * sin_l);
  vec4 c = u_light_view_proj * vec4(q, 1.0);
  vec3 s = c.xyz / c.w * 0.5 + 0.5;
  if (s.z > 1.0) return 1.0;
  float sum = 0.0;
  for (int y = -1; y <= 1; ++y) {
    for (int x = -1; x <= 1; ++x) {
      sum += texture(u_shadow_map, vec3(s.xy + vec2(x, y) * u_shadow_texel, s.z));
    }
  }
  return sum / 9.0;
}

// albedo: linear RGB; n: unit world normal facing the viewer's side; p: world position (m).
vec3 shade(vec3 albedo, vec3 n, vec3 p, float shininess, float specular) {
  vec3 l = -u_light_dir;
  vec3 v = normalize(u_eye - p);
  float ndl = max(dot(n, l), 0.0);
  float vis = ndl > 0.0 ? sun_visibility(p, n) : 0.0;
  vec3 h = normalize(l + v);
  float spec = ndl > 0.0 ? specular * pow(max(dot(n, h), 0.0), shininess) : 0.0;
  vec3 ambient = mix(vec3(0.07, 0.07, 0.08), vec3(0.24, 0.26, 0.30), 0.5 + 0.5 * n.y);
  float fill = 0.10 * max(dot(n, u_fill_dir), 0.0);
  vec3 sun = vec3(1.0, 0.97, 0.92) * 0.85;
  return albedo * (ambient + vec3(fill) + sun * (ndl * vis)) + vec3(spec * vis);
}

// Fog toward the background, then gamma encoding; alpha passes through.
vec4 finish(vec3 linear_rgb, vec3 p, float alpha) {
  float fog = smoothstep(u_fog.x, u_fog.y, distance(p, u_eye));
  vec3 c = mix(linear_rgb, u_background, fog);
  return vec4(pow(clamp(c, 0.0, 1.0), vec3(1.0 / 2.2)), alpha);
}
