// `cps export SCENE --out FILE.glb`: a run written as a glTF 2.0 binary (Khronos, "glTF 2.0
// Specification", 2021) for Blender and other 3D tools: one mesh per body shape, the renderer's
// colours as materials, the rods as cylinders, one animation of every body's and rod's pose
// sampled at --fps, and the scene's camera. The file is built and serialised with tinygltf
// (Debian's libtinygltf-dev) and written under the output rule (output.h).
// `cps export SCENE --fclib FILE.hdf5 --at STEPS`: chosen steps' solves as FCLIB problems
// (export_fclib.h).
#include "command.h"
#include "options/diagnostics.h"
#include "commands/export_fclib.h"
#include "pictures/draw.h"
#include "options/options.h"
#include "output/output.h"
#include "options/progress.h"
#include "scene_file.h"

#include "cps/constraint.h"

// tinygltf's implementation lives in this file only. Images are never read or written (the file
// has none), so tinygltf takes neither stb_image nor stb_image_write: the renderer's PNG code is
// the only image code in the binary.
#include <CLI/CLI.hpp>

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace cps::cli {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Segments around a sphere's equator and rings from pole to pole of its UV mesh; segments
/// around a rod's cylinder.
constexpr int kSphereSegments = 32;
constexpr int kSphereRings = 16;
constexpr int kRodSegments = 16;

/// Width / height of the camera's picture: that of `cps render`'s default 1280x720 frames.
constexpr double kAspect = 16.0 / 9.0;

/// Bytes one sample of the animation holds (floats): its time (4), a body's translation and
/// rotation (28), a rod's translation, rotation and scale (40).
constexpr double kSampleTimeBytes = 4.0;
constexpr double kSampleBodyBytes = 28.0;
constexpr double kSampleRodBytes = 40.0;
/// Most bytes of animation samples an export may hold: 512 MiB. Building the file holds them
/// about 4.5 times over (the samples, the glTF buffer, the serialised file), so about 2.3 GiB.
constexpr double kMaxSampleBytes = 536870912.0;

// The options of `cps export`.
struct ExportOptions {
  std::string scene;
  std::optional<double> seconds;  // s; default: the scene's
  double fps = 30.0;              // samples per simulated second
  std::string out;
  std::string fclib;  // --fclib FILE.hdf5
  std::string at;     // --at STEP,... (with --fclib)
  bool force = false;
  double max_work = kDefaultMaxWork;  // body-iterations
  scenes::Overrides overrides;
};

// A triangle mesh: positions (m) and unit normals per vertex, triangles as index triples.
struct Mesh {
  std::vector<float> positions;  // x, y, z per vertex
  std::vector<float> normals;    // x, y, z per vertex
  std::vector<std::uint32_t> indices;

  void vertex(const Vec3& p, const Vec3& n) {
    for (int k = 0; k < 3; ++k) positions.push_back(static_cast<float>(p[k]));
    for (int k = 0; k < 3; ++k) normals.push_back(static_cast<float>(n[k]));
  }
  std::uint32_t count() const { return static_cast<std::uint32_t>(positions.size() / 3); }
};

// A box of half extents h (m) centred on the origin: 4 vertices per face (24), each face with
// its own outward normal, so the faces shade flat.
Mesh box_mesh(const Vec3& h) {
  Mesh m;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = -1; side <= 1; side += 2) {
      Vec3 n = Vec3::Zero();
      n[axis] = side;
      // u, v span the face with u x v = n (counter-clockwise seen from outside).
      const int a = (axis + 1) % 3;
      const int b = (axis + 2) % 3;
      Vec3 u = Vec3::Zero();
      Vec3 v = Vec3::Zero();
      u[a] = 1.0;
      v[b] = side;
      const std::uint32_t base = m.count();
      const Vec3 c = n.cwiseProduct(h);
      const Vec3 hu = h[a] * u;
      const Vec3 hv = h[b] * v;
      m.vertex(c - hu - hv, n);
      m.vertex(c + hu - hv, n);
      m.vertex(c + hu + hv, n);
      m.vertex(c - hu + hv, n);
      for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    }
  }
  return m;
}

// A UV sphere of radius r (m) about the origin, poles on the y axis.
Mesh sphere_mesh(double r) {
  Mesh m;
  for (int ring = 0; ring <= kSphereRings; ++ring) {
    const double theta = kPi * ring / kSphereRings;  // from +y
    for (int seg = 0; seg <= kSphereSegments; ++seg) {
      const double phi = 2.0 * kPi * seg / kSphereSegments;
      const Vec3 n(std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi));
      m.vertex(r * n, n);
    }
  }
  const std::uint32_t row = kSphereSegments + 1;
  for (std::uint32_t ring = 0; ring < kSphereRings; ++ring) {
    for (std::uint32_t seg = 0; seg < static_cast<std::uint32_t>(kSphereSegments); ++seg) {
      const std::uint32_t a = ring * row + seg;
      const std::uint32_t b = a + row;
      for (std::uint32_t i : {a, b, a + 1, a + 1, b, b + 1}) m.indices.push_back(i);
    }
  }
  return m;
}

// A cylinder of radius r (m) and height 1 along y, from y = 0 to y = 1, side only: a rod's node
// scales it by the rod's length along y.
Mesh rod_mesh(double r) {
  Mesh m;
  for (int seg = 0; seg <= kRodSegments; ++seg) {
    const double phi = 2.0 * kPi * seg / kRodSegments;
    const Vec3 n(std::sin(phi), 0.0, std::cos(phi));
    m.vertex(r * n, n);
    m.vertex(r * n + Vec3::UnitY(), n);
  }
  for (std::uint32_t seg = 0; seg < static_cast<std::uint32_t>(kRodSegments); ++seg) {
    const std::uint32_t a = 2 * seg;
    for (std::uint32_t i : {a, a + 2, a + 1, a + 1, a + 2, a + 3}) m.indices.push_back(i);
  }
  return m;
}

// A square of half side `half` (m) in the plane {p : n . p = offset} (body frame, n unit),
// centred on the plane's point nearest to `centre`, facing n.
Mesh plane_mesh(const Vec3& n, double offset, const Vec3& centre, double half) {
  const Vec3 c = centre - (n.dot(centre) - offset) * n;
  const Vec3 u = n.unitOrthogonal();
  const Vec3 v = n.cross(u);  // u x v = n
  Mesh m;
  m.vertex(c - half * u - half * v, n);
  m.vertex(c + half * u - half * v, n);
  m.vertex(c + half * u + half * v, n);
  m.vertex(c - half * u + half * v, n);
  for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(i);
  return m;
}

// The one buffer of the file, and its views and accessors.
class Builder {
 public:
  explicit Builder(tinygltf::Model& model) : model_(model) { model_.buffers.emplace_back(); }

  // Appends `values` (count elements of `type`, floats) as an accessor; min and max per component
  // when `bounds`. Returns the accessor index.
  int floats(const std::vector<float>& values, int type, int components, bool bounds, int target) {
    const int count = static_cast<int>(values.size()) / components;
    const int view = add_view(values.data(), values.size() * sizeof(float), target);
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = static_cast<std::size_t>(count);
    a.type = type;
    if (bounds && count > 0) {
      a.minValues.assign(static_cast<std::size_t>(components), INFINITY);
      a.maxValues.assign(static_cast<std::size_t>(components), -INFINITY);
      for (int i = 0; i < count; ++i) {
        for (int k = 0; k < components; ++k) {
          const double x = values[static_cast<std::size_t>(i * components + k)];
          a.minValues[static_cast<std::size_t>(k)] = std::min(a.minValues[static_cast<std::size_t>(k)], x);
          a.maxValues[static_cast<std::size_t>(k)] = std::max(a.maxValues[static_cast<std::size_t>(k)], x);
        }
      }
    }
    model_.accessors.push_back(std::move(a));
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  // A mesh of one primitive (triangles) with the material `material`; returns its index.
  int mesh(const Mesh& m, int material, const std::string& name) {
    tinygltf::Primitive p;
    p.attributes["POSITION"] = floats(m.positions, TINYGLTF_TYPE_VEC3, 3, true,
                                      TINYGLTF_TARGET_ARRAY_BUFFER);
    p.attributes["NORMAL"] = floats(m.normals, TINYGLTF_TYPE_VEC3, 3, false,
                                    TINYGLTF_TARGET_ARRAY_BUFFER);
    const int view = add_view(m.indices.data(), m.indices.size() * sizeof(std::uint32_t),
                              TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.count = m.indices.size();
    a.type = TINYGLTF_TYPE_SCALAR;
    model_.accessors.push_back(std::move(a));
    p.indices = static_cast<int>(model_.accessors.size()) - 1;
    p.material = material;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(std::move(p));
    model_.meshes.push_back(std::move(mesh));
    return static_cast<int>(model_.meshes.size()) - 1;
  }

  // A material of base colour `rgb` (linear, each in [0, 1]) and opacity `alpha` ([0, 1];
  // below 1 blended), not metallic, rough; returns its index.
  int material(const glm::vec3& rgb, float alpha, const std::string& name) {
    tinygltf::Material m;
    m.name = name;
    m.pbrMetallicRoughness.baseColorFactor = {rgb.x, rgb.y, rgb.z, alpha};
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 0.8;
    if (alpha < 1.0f) m.alphaMode = "BLEND";
    m.doubleSided = alpha < 1.0f;
    model_.materials.push_back(std::move(m));
    return static_cast<int>(model_.materials.size()) - 1;
  }

 private:
  int add_view(const void* data, std::size_t bytes, int target) {
    std::vector<unsigned char>& buffer = model_.buffers.front().data;
    while (buffer.size() % 4 != 0) buffer.push_back(0);  // accessors aligned to their component
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), p, p + bytes);
    model_.bufferViews.push_back(v);
    return static_cast<int>(model_.bufferViews.size()) - 1;
  }

  tinygltf::Model& model_;
};

// Quaternion (cps: w, x, y, z) in glTF's order x, y, z, w, on the hemisphere of `previous`
// (x, y, z, w; none for the first sample) so that LINEAR (spherical) interpolation between two
// samples takes the short way.
void push_rotation(std::vector<float>& out, const Quat& q, bool continuous) {
  double c[4] = {q.x(), q.y(), q.z(), q.w()};
  if (continuous && out.size() >= 4) {
    const std::size_t p = out.size() - 4;
    double dot = 0.0;
    for (int k = 0; k < 4; ++k) dot += c[k] * out[p + static_cast<std::size_t>(k)];
    if (dot < 0.0) {
      for (double& x : c) x = -x;
    }
  }
  for (double x : c) out.push_back(static_cast<float>(x));
}

void push_vec(std::vector<float>& out, const Vec3& v) {
  for (int k = 0; k < 3; ++k) out.push_back(static_cast<float>(v[k]));
}

// The rotation (glTF node: x, y, z, w) of a camera at `eye` looking at `target` with `up` (m):
// glTF cameras look down their local -z with +y up.
std::vector<double> look_rotation(const glm::vec3& eye, const glm::vec3& target, const glm::vec3& up) {
  const Vec3 f = Vec3(target.x - eye.x, target.y - eye.y, target.z - eye.z).normalized();
  Vec3 r = f.cross(Vec3(up.x, up.y, up.z));
  if (r.norm() < 1e-9) r = f.unitOrthogonal();
  r.normalize();
  const Vec3 u = r.cross(f);
  Mat3 m;
  m.col(0) = r;
  m.col(1) = u;
  m.col(2) = -f;
  const Quat q(m);
  return {q.x(), q.y(), q.z(), q.w()};
}

// The radius (m) of the rods' cylinders: 2 % of the smallest movable body's size (largest half
// extent or radius), at most 0.02 m; 0.02 m when no body is movable.
double rod_radius(const World& world) {
  double size = INFINITY;
  for (const Body& b : world.bodies()) {
    if (b.is_static()) continue;
    if (b.shape.kind == ShapeKind::box) size = std::min(size, b.shape.half_extents.maxCoeff());
    if (b.shape.kind == ShapeKind::sphere) size = std::min(size, b.shape.radius);
  }
  return std::isfinite(size) ? std::min(0.02, 0.1 * size) : 0.02;
}

// An export as planned: options, scene, duration and samples checked, the file's folder checked
// (plan_output), nothing written. Sample k is the state at k / fps s, k = 0 .. samples - 1.
struct ExportPlan {
  const scenes::Scene* scene = nullptr;
  scenes::Run run;
  std::filesystem::path path;  // --out, FILE.glb
  std::size_t samples = 0;     // floor(seconds x fps) + 1, at most kMaxFrames and kMaxSampleBytes
  nlohmann::json info;         // the folder's run.json
  OutputPlan output;
};

// Checks the options, builds the run and checks its folder before anything is written. Throws
// UsageError.
ExportPlan plan_export(const ExportOptions& o, int argc, char** argv) {
  if (o.scene == "all" || o.scene == "stress") {
    throw UsageError("export takes one scene, not '" + o.scene + "'");
  }
  const std::filesystem::path path(o.out);
  if (path.extension() != ".glb" || path.stem().empty() || path.stem() == ".") {
    throw UsageError("--out " + o.out + ": give a file name ending in .glb (a glTF 2.0 binary)");
  }
  const scenes::Scene* scene = select_scenes(o.scene).front();
  scenes::Run run = make_run_or_usage_error(*scene, o.overrides);
  const double seconds = o.seconds.value_or(scene->default_seconds);
  check_steps(o.scene, seconds, run.world.def().dt);
  check_work(o.scene, run.world.bodies().size(), run.world.def(), seconds, o.max_work,
             lower_run_options(run.world.def()));
  // Sample k at t_k = k / fps, k = 0 .. floor(seconds * fps).
  const double frames = std::floor(seconds * o.fps + 1e-9) + 1.0;
  if (frames > kMaxFrames) {
    throw UsageError(std::to_string(static_cast<long long>(frames)) +
                     " samples (--seconds x --fps) is more than the " +
                     std::to_string(static_cast<long long>(kMaxFrames)) +
                     " an export may write; give fewer --seconds or a lower --fps");
  }
  const double bodies = static_cast<double>(run.world.bodies().size());
  const double rods = static_cast<double>(run.world.distances().size());
  const double sample_bytes =
      frames * (kSampleTimeBytes + kSampleBodyBytes * bodies + kSampleRodBytes * rods);
  if (sample_bytes > kMaxSampleBytes) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "%.0f samples x (%.0f B + %.0f bodies x %.0f B + %.0f rods x %.0f B) is %.0f MiB of "
                  "animation samples, more than the %.0f MiB an export may hold (building the "
                  "file takes about 4.5 times that in memory); give fewer --seconds or a lower "
                  "--fps",
                  frames, kSampleTimeBytes, bodies, kSampleBodyBytes, rods, kSampleRodBytes,
                  sample_bytes / 1048576.0, kMaxSampleBytes / 1048576.0);
    throw UsageError(o.scene + ": " + text);
  }
  nlohmann::json info = run_info("export", argc, argv,
                                 {{"scene", scene->name},
                                  {"seconds", seconds},
                                  {"fps", o.fps},
                                  {"out", o.out},
                                  {"overrides", overrides_json(o.overrides)},
                                  {"parameters", parameters_json(run.world.def())}});
  const std::string file = path.filename().string();
  OutputPlan output = plan_output({.folder = path.parent_path(),
                                   .files = {file},
                                   .command = "export",
                                   .use = FolderUse::shared,
                                   .scenes = {{file, scene_source(scene->name)}},
                                   .force = o.force});
  return {scene, std::move(run), path, static_cast<std::size_t>(frames), std::move(info), std::move(output)};
}

// Bodies: a node each (nodes 0 .. bodies - 1), with its shape's mesh in the body frame and a
// material of its colour in `style` (one "plane" material for every plane), named by the scene.
void add_body_nodes(const scenes::Scene& scene, const World& world, const DrawStyle& style,
                    tinygltf::Model& model, Builder& build, tinygltf::Scene& gscene) {
  const std::vector<Body>& bodies = world.bodies();
  const std::vector<std::string> names = scenes::body_names(scene);
  const render::PlaneItem plane_look;  // the renderer's plane colours
  const glm::vec3 plane_rgb = 0.5f * (plane_look.color_a + plane_look.color_b);
  int plane_material = -1;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    const std::string name =
        i < names.size() && !names[i].empty() ? names[i] : "body_" + std::to_string(i);
    Mesh mesh;
    int material = -1;
    if (b.shape.kind == ShapeKind::box) {
      mesh = box_mesh(b.shape.half_extents);
    } else if (b.shape.kind == ShapeKind::sphere) {
      mesh = sphere_mesh(b.shape.radius);
    } else {
      // As draw_list draws it: a square of half side plane_half_size_m centred on the plane's
      // point nearest to plane_centre, here in the body frame (n . p = offset).
      const Vec3 centre(style.plane_centre.x, style.plane_centre.y, style.plane_centre.z);
      mesh = plane_mesh(b.shape.normal.normalized(), b.shape.offset,
                        b.rotation().transpose() * (centre - b.x), style.plane_half_size_m);
      if (plane_material < 0) {
        plane_material = build.material(plane_rgb, style.plane_opacity, "plane");
      }
      material = plane_material;
    }
    if (material < 0) material = build.material(body_colour(i, style), 1.0f, name);
    tinygltf::Node node;
    node.name = name;
    node.mesh = build.mesh(mesh, material, name);
    gscene.nodes.push_back(static_cast<int>(model.nodes.size()));
    model.nodes.push_back(std::move(node));
  }
}

// Rods: a node each, "rod_R", sharing one mesh, the unit cylinder along +y that the animation
// turns onto p_b - p_a and scales to the length, in the colour draw_list gives rods. Returns
// the first rod's node.
int add_rod_nodes(const World& world, const DrawStyle& style, tinygltf::Model& model, Builder& build,
                  tinygltf::Scene& gscene) {
  const std::vector<DistanceConstraint>& rods = world.distances();
  const render::DrawList as_built = draw_list(world, style);
  const glm::vec3 rod_rgb = as_built.lines.empty() ? glm::vec3(0.15f) : as_built.lines.front().color;
  const int rod_mesh_index =
      rods.empty() ? -1 : build.mesh(rod_mesh(rod_radius(world)), build.material(rod_rgb, 1.0f, "rod"), "rod");
  const int first_rod_node = static_cast<int>(model.nodes.size());
  for (std::size_t r = 0; r < rods.size(); ++r) {
    tinygltf::Node node;
    node.name = "rod_" + std::to_string(r);
    node.mesh = rod_mesh_index;
    gscene.nodes.push_back(static_cast<int>(model.nodes.size()));
    model.nodes.push_back(std::move(node));
  }
  return first_rod_node;
}

// The camera: the scene's view in `style` (as `cps render` shows it), at kAspect.
void add_camera_node(const DrawStyle& style, tinygltf::Model& model, tinygltf::Scene& gscene) {
  tinygltf::Camera camera;
  camera.name = "camera";
  camera.type = "perspective";
  camera.perspective.yfov = style.camera.fov_y_deg * kPi / 180.0;
  camera.perspective.aspectRatio = kAspect;
  camera.perspective.znear = style.camera.near_m;
  camera.perspective.zfar = style.camera.far_m;
  model.cameras.push_back(camera);
  tinygltf::Node node;
  node.name = "camera";
  node.camera = 0;
  node.translation = {style.camera.eye.x, style.camera.eye.y, style.camera.eye.z};
  node.rotation = look_rotation(style.camera.eye, style.camera.target, style.camera.up);
  gscene.nodes.push_back(static_cast<int>(model.nodes.size()));
  model.nodes.push_back(std::move(node));
}

// The animation's samples: times (s), and per body its translation (m; x, y, z a sample) and
// rotation (x, y, z, w), per rod its first end (m), rotation from +y and scale (1, length, 1).
struct Samples {
  std::vector<float> times;
  std::vector<std::vector<float>> translation, rotation;
  std::vector<std::vector<float>> rod_t, rod_r, rod_s;
};

// Steps the plan's run through its samples, each the state after the step nearest to its time
// (as Run::advance_to), with progress on stderr.
Samples sample_run(ExportPlan& plan, double fps, const std::string& scene_option) {
  const std::vector<Body>& bodies = plan.run.world.bodies();
  const std::vector<DistanceConstraint>& rods = plan.run.world.distances();
  Samples s;
  s.translation.resize(bodies.size());
  s.rotation.resize(bodies.size());
  s.rod_t.resize(rods.size());
  s.rod_r.resize(rods.size());
  s.rod_s.resize(rods.size());
  Progress progress("export " + scene_option, static_cast<long long>(plan.samples), "samples", 2.0);
  for (std::size_t k = 0; k < plan.samples; ++k) {
    const double t = static_cast<double>(k) / fps;
    plan.run.advance_to(t);
    s.times.push_back(static_cast<float>(t));
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      push_vec(s.translation[i], bodies[i].x);
      push_rotation(s.rotation[i], bodies[i].o, true);
    }
    for (std::size_t r = 0; r < rods.size(); ++r) {
      Vec3 p_a;
      Vec3 p_b;
      distance_endpoints(rods[r], bodies, p_a, p_b);
      const Vec3 d = p_b - p_a;
      const double length = d.norm();
      const Quat q = length > 0.0 ? Quat::FromTwoVectors(Vec3::UnitY(), d) : Quat::Identity();
      push_vec(s.rod_t[r], p_a);
      push_rotation(s.rod_r[r], q, true);
      push_vec(s.rod_s[r], Vec3(1.0, length, 1.0));
    }
    progress.update(static_cast<long long>(k + 1));
  }
  progress.finish();
  return s;
}

// The one animation, named after the scene: a LINEAR channel per body (translation, rotation;
// nodes 0 ..) and per rod (translation, rotation, scale; nodes first_rod_node ..).
void add_animation(const Samples& s, int first_rod_node, const std::string& name,
                   tinygltf::Model& model, Builder& build) {
  tinygltf::Animation animation;
  animation.name = name;
  const int time_accessor = build.floats(s.times, TINYGLTF_TYPE_SCALAR, 1, true, -1);
  auto channel = [&](int node, const char* path_name, const std::vector<float>& values, int type,
                     int components) {
    tinygltf::AnimationSampler sampler;
    sampler.input = time_accessor;
    sampler.output = build.floats(values, type, components, false, -1);
    sampler.interpolation = "LINEAR";
    animation.samplers.push_back(sampler);
    tinygltf::AnimationChannel c;
    c.sampler = static_cast<int>(animation.samplers.size()) - 1;
    c.target_node = node;
    c.target_path = path_name;
    animation.channels.push_back(c);
  };
  for (std::size_t i = 0; i < s.translation.size(); ++i) {
    channel(static_cast<int>(i), "translation", s.translation[i], TINYGLTF_TYPE_VEC3, 3);
    channel(static_cast<int>(i), "rotation", s.rotation[i], TINYGLTF_TYPE_VEC4, 4);
  }
  for (std::size_t r = 0; r < s.rod_t.size(); ++r) {
    const int node = first_rod_node + static_cast<int>(r);
    channel(node, "translation", s.rod_t[r], TINYGLTF_TYPE_VEC3, 3);
    channel(node, "rotation", s.rod_r[r], TINYGLTF_TYPE_VEC4, 4);
    channel(node, "scale", s.rod_s[r], TINYGLTF_TYPE_VEC3, 3);
  }
  model.animations.push_back(std::move(animation));
}

// The model as a glTF 2.0 binary (tinygltf), its buffer padded to 4 bytes first. Throws
// std::runtime_error naming `out` if tinygltf cannot serialise it.
std::string glb_bytes(tinygltf::Model& model, const std::string& out) {
  model.buffers.front().data.resize((model.buffers.front().data.size() + 3) / 4 * 4, 0);
  std::ostringstream bytes;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, bytes, false, true)) {
    throw std::runtime_error("cannot write " + out + ": tinygltf could not serialise the model");
  }
  return bytes.str();
}

// Builds the model (bodies, rods, camera), steps the run through the samples, writes the file
// under the output rule and prints what it holds on stderr. Throws std::runtime_error.
int execute_export(const ExportOptions& o, ExportPlan& plan) {
  const scenes::Scene& scene = *plan.scene;
  const World& world = plan.run.world;
  const DrawStyle style = resolve_style(scene, world, View{}, static_cast<float>(kAspect));

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = std::string("cps export ") + engine_version();
  Builder build(model);
  tinygltf::Scene gscene;
  gscene.name = std::string(scene.name);
  add_body_nodes(scene, world, style, model, build, gscene);
  const int first_rod_node = add_rod_nodes(world, style, model, build, gscene);
  add_camera_node(style, model, gscene);

  const Samples samples = sample_run(plan, o.fps, o.scene);
  add_animation(samples, first_rod_node, std::string(scene.name), model, build);
  model.scenes.push_back(std::move(gscene));
  model.defaultScene = 0;

  const std::string data = glb_bytes(model, o.out);
  begin_output(plan.output, plan.info);
  write_file_atomic(plan.path, std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
  end_output(plan.output, plan.info);
  notes() << "export " << scene.name << ": " << world.bodies().size() << " bodies, "
            << world.distances().size() << " rods, " << plan.samples << " samples at " << o.fps
            << " fps (" << data.size() << " bytes) in " << o.out << "\n";
  return 0;
}

int run_export(const ExportOptions& o, int argc, char** argv) {
  if (!o.fclib.empty()) {
    return run_fclib_export({.scene = o.scene,
                             .seconds = o.seconds,
                             .at = o.at,
                             .path = o.fclib,
                             .force = o.force,
                             .max_work = o.max_work,
                             .overrides = o.overrides},
                            argc, argv);
  }
  if (o.out.empty()) {
    throw UsageError("export needs --out FILE.glb (a glTF 2.0 binary) or --fclib FILE.hdf5 "
                     "(FCLIB problems of the steps of --at)");
  }
  ExportPlan plan = plan_export(o, argc, argv);
  return execute_export(o, plan);
}

}  // namespace

Command add_export(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* sub = app.add_subcommand(
      "export", "write a run as a glTF 2.0 binary (.glb) for Blender and other 3D tools, or "
                "chosen steps' contact problems as FCLIB files (.hdf5)");
  sub->add_option("scene", o->scene,
                  "scene name (see 'cps list') or the path of a scene file (.json)")
      ->required();
  add_seed_option(*sub, o->scene);
  add_seconds_option(*sub, o->seconds,
                     "at most 1e7 steps (--seconds / --dt), 1e5 samples (--seconds x --fps) and "
                     "512 MiB of samples (samples x (28 B a body + 40 B a rod))");
  CLI::Option* fps = sub->add_option("--fps", o->fps,
                  "animation samples per simulated second, in [1e-5, 1000]; sample k is the state "
                  "after the physics step nearest to k / fps s, and tools interpolate between "
                  "samples (LINEAR)")
      ->check(decimal_in(1.0 / kMaxSeconds, kMaxFps, false, "samples/s"))
      ->capture_default_str();
  CLI::Option* out = sub->add_option("--out", o->out,
                  "the glTF 2.0 binary to write (FILE.glb): a mesh per body, rods as cylinders, "
                  "materials in the renderer's colours, the animation and the scene's camera; "
                  "missing folders are created, and the folder's run.json lists the files cps "
                  "wrote there")
      ->check(kNotEmpty);
#ifdef CPS_HAVE_FCLIB
  const std::string fclib_help =
      "instead of --out: write the first solve of each step of --at as a local frictional "
      "contact problem of FCLIB (FILE.hdf5; several steps: STEM-stepN.hdf5 beside it): W = A "
      "(1/kg) and q = -dt b (m/s) on each contact's normal and two tangent rows, mu per contact, "
      "rods as V, R, s (docs/exact_reference.md); --force as for --out";
#else
  const std::string fclib_help =
      "instead of --out: FCLIB problems of the steps of --at (FILE.hdf5); left out of this "
      "build (libfclib-dev was not found when cps was configured)";
#endif
  CLI::Option* fclib = sub->add_option("--fclib", o->fclib, fclib_help)
                           ->check(kNotEmpty)
                           ->excludes(out)
                           ->excludes(fps);
  sub->add_option("--at", o->at,
                  "with --fclib: the steps whose solves are written, comma-separated step "
                  "indices in [0, steps - 1] (0 is the first step; default: the last), at most " +
                      std::to_string(kMaxFclibSteps))
      ->check(kNotEmpty)
      ->needs(fclib);
  sub->add_flag("--force", o->force,
                "let --out or --fclib replace a file of that name that no earlier cps run wrote (the "
                "folder's run.json lists the files cps wrote there; those are replaced without "
                "it); any other file is never touched");
  add_max_work_option(*sub, o->max_work);
  add_world_options(*sub, o->overrides);
  add_diagnostic_flags(*sub);
  return {sub, [o, argc, argv] { return run_export(*o, argc, argv); }};
}

}  // namespace cps::cli
