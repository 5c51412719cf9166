// `cps export SCENE --out FILE.glb` as a user runs it: the glTF 2.0 binary read back with
// tinygltf, its poses checked against the per-step trace of `cps simulate` of the same scene,
// its meshes against the scene's shapes, its rods against their end points; and bad input
// (exit 2, nothing written).
#include "cli_support.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

// The reading half of tinygltf, for this test only; images are never read (the files have none).
#include <tiny_gltf.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cli_test::Result;
using cli_test::run_cps;
using nlohmann::json;

namespace {

// The pose of one body at one step of a trace: position (m), orientation w, x, y, z.
struct Pose {
  std::array<double, 3> x{};
  std::array<double, 4> q{};  // w, x, y, z as the trace writes it
};

// A `cps simulate --trace` CSV: time (s) and poses by step, bodies by index.
struct Trace {
  std::map<long, double> time;
  std::map<long, std::vector<Pose>> poses;
};

Trace read_trace(const fs::path& p) {
  std::istringstream in(cli_test::slurp(p));
  std::string line;
  std::getline(in, line);  // header
  Trace t;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) v.push_back(std::stod(cell));
    REQUIRE(v.size() == 16);
    const long step = static_cast<long>(v[0]);
    t.time[step] = v[1];
    Pose pose;
    pose.x = {v[3], v[4], v[5]};
    pose.q = {v[6], v[7], v[8], v[9]};
    auto& row = t.poses[step];
    REQUIRE(static_cast<std::size_t>(v[2]) == row.size());
    row.push_back(pose);
  }
  return t;
}

// The step of the trace whose time is nearest to t (s).
long step_at(const Trace& trace, double t) {
  long best = -1;
  double gap = INFINITY;
  for (const auto& [step, time] : trace.time) {
    if (std::abs(time - t) < gap) {
      gap = std::abs(time - t);
      best = step;
    }
  }
  return best;
}

// The floats of accessor `index` (tightly packed FLOAT data, as cps writes them).
std::vector<float> floats(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& a = m.accessors.at(static_cast<std::size_t>(index));
  REQUIRE(a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& v = m.bufferViews.at(static_cast<std::size_t>(a.bufferView));
  const tinygltf::Buffer& b = m.buffers.at(static_cast<std::size_t>(v.buffer));
  const std::size_t n = a.count * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(
                                      static_cast<std::uint32_t>(a.type)));
  std::vector<float> out(n);
  REQUIRE(v.byteOffset + a.byteOffset + n * sizeof(float) <= b.data.size());
  std::memcpy(out.data(), b.data.data() + v.byteOffset + a.byteOffset, n * sizeof(float));
  return out;
}

// The output values of the animation's channel for `node` and `path` ("translation", ...).
std::vector<float> channel(const tinygltf::Model& m, int node, const std::string& path) {
  const tinygltf::Animation& a = m.animations.at(0);
  for (const tinygltf::AnimationChannel& c : a.channels) {
    if (c.target_node == node && c.target_path == path) {
      const tinygltf::AnimationSampler& s = a.samplers.at(static_cast<std::size_t>(c.sampler));
      CHECK(s.interpolation == "LINEAR");
      return floats(m, s.output);
    }
  }
  FAIL("no " << path << " channel for node " << node);
  return {};
}

tinygltf::Model load(const fs::path& p) {
  tinygltf::Model m;
  tinygltf::TinyGLTF loader;
  std::string err;
  std::string warn;
  const bool ok = loader.LoadBinaryFromFile(&m, &err, &warn, p.string());
  INFO(err << warn);
  REQUIRE(ok);
  return m;
}

// Float precision of the file: a value v written as a float is within this of v (m or unit
// quaternion components): 1e-6 relative, or 1e-5 absolute.
bool close(double a, double b) {
  return std::abs(a - b) <= std::max(1e-5, 1e-6 * std::abs(b));
}

// v rotated by the unit quaternion (w, x, y, z).
std::array<double, 3> rotate(const std::array<double, 4>& q, const std::array<double, 3>& v) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  // t = 2 (q_v x v); v' = v + w t + q_v x t
  const double tx = 2 * (y * v[2] - z * v[1]);
  const double ty = 2 * (z * v[0] - x * v[2]);
  const double tz = 2 * (x * v[1] - y * v[0]);
  return {v[0] + w * tx + (y * tz - z * ty), v[1] + w * ty + (z * tx - x * tz),
          v[2] + w * tz + (x * ty - y * tx)};
}

struct Exported {
  tinygltf::Model model;
  Trace trace;
  json scene;  // `cps scene SCENE`: bodies and rods as built
};

// Exports `scene` for 1 s at 10 samples/s, traces the same run, and reads both back.
Exported export_and_trace(const std::string& scene, const fs::path& dir) {
  const Result e = run_cps("export " + scene + " --seconds 1 --fps 10 --out out/" + scene + ".glb", dir);
  INFO(e.err);
  REQUIRE(e.exit_code == 0);
  const Result s = run_cps("simulate " + scene + " --seconds 1 --trace " + scene + ".csv", dir);
  REQUIRE(s.exit_code == 0);
  const Result j = run_cps("scene " + scene, dir);
  REQUIRE(j.exit_code == 0);
  return {load(dir / "out" / (scene + ".glb")), read_trace(dir / (scene + ".csv")), json::parse(j.out)};
}

// Every body node's translation and rotation at every sample against the trace at that time.
void check_poses(const Exported& x) {
  const tinygltf::Model& m = x.model;
  REQUIRE(m.animations.size() == 1);
  const std::size_t bodies = x.scene["bodies"].size();
  // Its time accessor: frames = seconds x fps + 1 samples, t_k = k / fps.
  const tinygltf::AnimationSampler& s0 = m.animations[0].samplers.at(0);
  const std::vector<float> times = floats(m, s0.input);
  REQUIRE(times.size() == 11);
  for (std::size_t k = 0; k < times.size(); ++k) CHECK(close(times[k], 0.1 * static_cast<double>(k)));
  for (std::size_t i = 0; i < bodies; ++i) {
    const std::vector<float> t = channel(m, static_cast<int>(i), "translation");
    const std::vector<float> r = channel(m, static_cast<int>(i), "rotation");
    REQUIRE(t.size() == 3 * times.size());
    REQUIRE(r.size() == 4 * times.size());
    for (std::size_t k = 0; k < times.size(); ++k) {
      const long step = step_at(x.trace, 0.1 * static_cast<double>(k));
      INFO("body " << i << ", sample " << k << ", trace step " << step);
      REQUIRE(std::abs(x.trace.time.at(step) - 0.1 * static_cast<double>(k)) < 1e-9);
      const Pose& p = x.trace.poses.at(step).at(i);
      for (int c = 0; c < 3; ++c) CHECK(close(t[3 * k + static_cast<std::size_t>(c)], p.x[static_cast<std::size_t>(c)]));
      // glTF: x, y, z, w; the trace: w, x, y, z. q and -q are the same rotation: the file keeps
      // successive samples on one hemisphere, so compare with the sign that matches.
      const std::array<double, 4> g = {r[4 * k + 3], r[4 * k], r[4 * k + 1], r[4 * k + 2]};
      double dot = 0.0;
      for (int c = 0; c < 4; ++c) dot += g[static_cast<std::size_t>(c)] * p.q[static_cast<std::size_t>(c)];
      const double sign = dot < 0.0 ? -1.0 : 1.0;
      for (int c = 0; c < 4; ++c) CHECK(close(g[static_cast<std::size_t>(c)], sign * p.q[static_cast<std::size_t>(c)]));
    }
  }
}

}  // namespace

TEST_CASE("cps export intersecting_stack: boxes, their poses as the trace's, the camera",
          "[cli][export]") {
  const fs::path dir = cli_test::fresh_dir("cps_cli_export_stack");
  const Exported x = export_and_trace("intersecting_stack", dir);
  const tinygltf::Model& m = x.model;
  const json& bodies = x.scene["bodies"];
  const std::size_t rods = x.scene.value("rods", json::array()).size();
  // A node per body, per rod, and the camera.
  REQUIRE(m.nodes.size() == bodies.size() + rods + 1);
  REQUIRE(m.scenes.size() == 1);
  CHECK(m.scenes[0].nodes.size() == m.nodes.size());
  check_poses(x);
  // Each box's mesh spans its half extents (the body frame), to float precision.
  int boxes = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const tinygltf::Node& node = m.nodes[i];
    CHECK(node.name == "body_" + std::to_string(i));  // the paper's scene names no body
    if (bodies[i]["shape"] != "box") continue;
    ++boxes;
    const tinygltf::Accessor& pos =
        m.accessors.at(static_cast<std::size_t>(m.meshes.at(static_cast<std::size_t>(node.mesh)).primitives.at(0).attributes.at("POSITION")));
    CHECK(pos.count == 24);
    REQUIRE(pos.minValues.size() == 3);
    REQUIRE(pos.maxValues.size() == 3);
    for (std::size_t c = 0; c < 3; ++c) {
      const double h = bodies[i]["half_extents_m"][c];
      CHECK(close(pos.maxValues[c], h));
      CHECK(close(pos.minValues[c], -h));
    }
    // Its material: an opaque colour.
    const tinygltf::Material& mat = m.materials.at(static_cast<std::size_t>(m.meshes[static_cast<std::size_t>(node.mesh)].primitives[0].material));
    CHECK(mat.pbrMetallicRoughness.baseColorFactor.at(3) == 1.0);
  }
  CHECK(boxes >= 2);
  // The camera: the last node, looking (down its -z) at the scene's target.
  const tinygltf::Node& cam = m.nodes.back();
  REQUIRE(cam.camera == 0);
  REQUIRE(m.cameras.at(0).type == "perspective");
  CHECK(m.cameras[0].perspective.yfov > 0.0);
  REQUIRE(cam.rotation.size() == 4);
  REQUIRE(cam.translation.size() == 3);
  const std::array<double, 4> q = {cam.rotation[3], cam.rotation[0], cam.rotation[1], cam.rotation[2]};
  const std::array<double, 3> forward = rotate(q, {0.0, 0.0, -1.0});
  const std::array<double, 3> up = rotate(q, {0.0, 1.0, 0.0});
  CHECK(up[1] > 0.0);  // not upside down
  // The scene's view looks at its target: the stack, near the origin, below the eye.
  if (x.scene.contains("camera")) {
    const json& c = x.scene["camera"];
    std::array<double, 3> d{};
    double len = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      d[k] = double(c["target_m"][k]) - double(c["eye_m"][k]);
      len += d[k] * d[k];
      CHECK(close(cam.translation[k], c["eye_m"][k]));
    }
    for (std::size_t k = 0; k < 3; ++k) CHECK(std::abs(forward[k] - d[k] / std::sqrt(len)) < 1e-6);
  }
}

TEST_CASE("cps export chain_hit: named nodes, rods as cylinders between their end points",
          "[cli][export]") {
  const fs::path dir = cli_test::fresh_dir("cps_cli_export_chain");
  const Exported x = export_and_trace("chain_hit", dir);
  const tinygltf::Model& m = x.model;
  const json& bodies = x.scene["bodies"];
  const json& rods = x.scene["rods"];
  REQUIRE(rods.size() >= 1);
  REQUIRE(m.nodes.size() == bodies.size() + rods.size() + 1);
  check_poses(x);
  CHECK(m.nodes[0].name == "ground");
  CHECK(m.nodes[1].name == "link0");
  // Rod r is node bodies + r: its cylinder (height 1 along +y) is placed at p_a, turned and
  // scaled so that its far end is p_b, at every sample.
  for (std::size_t r = 0; r < rods.size(); ++r) {
    const int node = static_cast<int>(bodies.size() + r);
    const std::vector<float> t = channel(m, node, "translation");
    const std::vector<float> q = channel(m, node, "rotation");
    const std::vector<float> s = channel(m, node, "scale");
    const json& rod = rods[r];
    for (std::size_t k = 0; k < 11; ++k) {
      INFO("rod " << r << ", sample " << k);
      const std::vector<Pose>& poses = x.trace.poses.at(step_at(x.trace, 0.1 * static_cast<double>(k)));
      auto end = [&](const json& body, const json& point) {
        const std::array<double, 3> local = {point[0], point[1], point[2]};
        if (body.is_null()) return local;
        const Pose& p = poses.at(body.get<std::size_t>());
        const std::array<double, 3> w = rotate(p.q, local);
        return std::array<double, 3>{p.x[0] + w[0], p.x[1] + w[1], p.x[2] + w[2]};
      };
      const std::array<double, 3> pa = end(rod["body_a"], rod["point_a_m"]);
      const std::array<double, 3> pb = end(rod["body_b"], rod["point_b_m"]);
      const std::array<double, 4> qr = {q[4 * k + 3], q[4 * k], q[4 * k + 1], q[4 * k + 2]};
      const std::array<double, 3> axis = rotate(qr, {0.0, s[3 * k + 1], 0.0});
      for (std::size_t c = 0; c < 3; ++c) {
        CHECK(close(t[3 * k + c], pa[c]));
        CHECK(std::abs(t[3 * k + c] + axis[c] - pb[c]) <= 1e-5);
      }
      CHECK(s[3 * k] == 1.0f);
      CHECK(s[3 * k + 2] == 1.0f);
    }
  }
}

TEST_CASE("cps export refuses bad input with exit 2 and writes nothing", "[cli][export]") {
  const fs::path dir = cli_test::fresh_dir("cps_cli_export_bad");
  struct Case {
    std::string args;
    std::string says;
  };
  const Case cases[] = {
      {"export stack --out x.png", "x.png"},
      {"export stack --out x", "ending in .glb"},
      {"export stack --fps 0 --out x.glb", "--fps"},
      {"export missing.json --out x.glb", "missing.json"},
      {"export nosuch --out x.glb", "nosuch"},
      {"export all --out x.glb", "all"},
      {"export stack --seconds 1e5 --fps 1000 --out x.glb", "samples"},
  };
  for (const Case& c : cases) {
    INFO(c.args);
    const Result r = run_cps(c.args, dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
    CHECK(fs::is_empty(dir));
  }
  // A file cps did not write is kept without --force, replaced with it.
  { std::ofstream(dir / "mine.glb") << "not cps's"; }
  CHECK(run_cps("export stack --seconds 0.1 --out mine.glb", dir).exit_code == 2);
  CHECK(cli_test::slurp(dir / "mine.glb") == "not cps's");
  CHECK(run_cps("export stack --seconds 0.1 --out mine.glb --force", dir).exit_code == 0);
  CHECK(cli_test::slurp(dir / "mine.glb").substr(0, 4) == "glTF");
}
