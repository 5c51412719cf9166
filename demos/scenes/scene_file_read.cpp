// Reading scene files: the values and bodies of a checked document, parse_scene_file and
// read_scene_file; the Scene of a file (scene_of, its FileSceneMetrics) and the registry that
// keeps loaded and example files for the program's life, with its accessors.
#include "scene_file.h"

#include "scene_file_errors.h"

#include "cps_scene_assets.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <system_error>

namespace cps::scenes {
namespace {

using nlohmann::json;
using detail::fail;
using detail::joined;
using detail::parse_json_text;
using detail::shown;
using detail::validate_against_schema;

// ---- Reading values (after the schema: types and sizes are right) ---------------------------

Vec3 vec3_of(const json& j) { return Vec3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>()); }

// "#rrggbb" (sRGB) as linear RGB.
Vec3 colour_of(const std::string& text) {
  Vec3 c;
  for (int k = 0; k < 3; ++k) {
    const double srgb =
        static_cast<double>(std::stoi(text.substr(1 + 2 * static_cast<std::size_t>(k), 2), nullptr, 16)) / 255.0;
    c[k] = srgb <= 0.04045 ? srgb / 12.92 : std::pow((srgb + 0.055) / 1.055, 2.4);
  }
  return c;
}

ParameterValue parameter_value(const Parameter& p, const json& j) {
  switch (p.type) {
    case ParameterType::real:
      return j.get<double>();
    case ParameterType::integer: {
      const double v = j.get<double>();
      if (!(v >= p.min && v <= p.max) || v != std::floor(v)) return v;  // check() refuses it
      return static_cast<int>(v);
    }
    case ParameterType::boolean:
      return j.get<bool>();
    case ParameterType::vector3:
      return vec3_of(j);
    case ParameterType::choice:
      return p.find_choice(j.get<std::string>())->value;
  }
  return 0;
}

// The key of a body that make_body's message is about (its messages start with the value's name).
std::string key_of_body_error(const std::string& message, ShapeKind kind) {
  const std::array<std::pair<const char*, const char*>, 8> prefixes = {{
      {"body position", "position_m"},
      {"body velocity", "velocity_mps"},
      {"body angular velocity", "angular_velocity_radps"},
      {"body orientation", "orientation_wxyz"},
      {"body mass", "mass_kg"},
      {"body of mass", "mass_kg"},
      {"plane normal", "normal"},
      {"plane offset", "offset_m"},
  }};
  for (const auto& [prefix, key] : prefixes) {
    if (message.rfind(prefix, 0) == 0) return key;
  }
  if (kind == ShapeKind::box) return "half_extents_m";
  if (kind == ShapeKind::sphere) return "radius_m";
  return "";
}

// The keys that belong to one shape only.
const std::map<std::string, ShapeKind>& shape_keys() {
  static const std::map<std::string, ShapeKind> keys = {{"half_extents_m", ShapeKind::box},
                                                        {"radius_m", ShapeKind::sphere},
                                                        {"normal", ShapeKind::plane},
                                                        {"offset_m", ShapeKind::plane}};
  return keys;
}

FileBody read_body(const std::string& origin, const json& j, std::size_t index, World& check) {
  const std::string at = "/bodies/" + std::to_string(index);
  FileBody body;
  const std::string shape = j["shape"];
  const ShapeKind kind = shape == "box" ? ShapeKind::box
                         : shape == "sphere" ? ShapeKind::sphere
                                             : ShapeKind::plane;
  for (const auto& [key, k] : shape_keys()) {
    if (j.contains(key) && k != kind) {
      std::string own;
      for (const auto& [other, ok] : shape_keys()) {
        if (ok == kind) own += (own.empty() ? "" : " and ") + other;
      }
      fail(origin, at + "/" + key, "a " + shape + " takes " + own + ", not " + key);
    }
  }
  BodyDef& d = body.def;
  if (kind == ShapeKind::box) {
    d.shape.kind = ShapeKind::box;
    d.shape.half_extents = vec3_of(j["half_extents_m"]);
  } else if (kind == ShapeKind::sphere) {
    d.shape.kind = ShapeKind::sphere;
    d.shape.radius = j["radius_m"];
  } else {
    const Vec3 n = vec3_of(j["normal"]);
    const double offset = j.value("offset_m", 0.0);
    try {
      d.shape = Shape::plane(n, offset);
    } catch (const std::invalid_argument& e) {
      fail(origin, at + "/" + key_of_body_error(e.what(), kind), shown(j["normal"]) + " is not allowed: " + e.what());
    }
  }
  const double mass = j.value("mass_kg", 0.0);
  const bool is_static = j.value("static", kind == ShapeKind::plane);
  if (kind == ShapeKind::plane && !is_static) {
    fail(origin, at + "/static", "a plane is static by nature: omit \"static\" or set it true");
  }
  if (is_static && mass != 0.0) {
    fail(origin, at + "/mass_kg",
         shown(j["mass_kg"]) + " is not allowed: a static body has no mass (omit mass_kg or give 0)");
  }
  if (!is_static && !j.contains("mass_kg")) {
    fail(origin, at, "the key \"mass_kg\" is missing: a movable body needs a mass in [" +
                         std::to_string(kMinMass).substr(0, 8) + ", 1e9] kg (or \"static\": true)");
  }
  if (is_static) {
    for (const char* key : {"velocity_mps", "angular_velocity_radps"}) {
      if (j.contains(key) && vec3_of(j[key]) != Vec3::Zero()) {
        fail(origin, at + "/" + key, shown(j[key]) + " is not allowed: a static body never moves (omit it)");
      }
    }
  }
  d.is_static = is_static;
  d.mass = is_static ? 1.0 : mass;
  if (j.contains("position_m")) d.position = vec3_of(j["position_m"]);
  if (j.contains("velocity_mps")) d.velocity = vec3_of(j["velocity_mps"]);
  if (j.contains("angular_velocity_radps")) d.angular_velocity = vec3_of(j["angular_velocity_radps"]);
  if (j.contains("restitution")) d.restitution = j["restitution"].get<double>();  // [0, 1]: the schema
  if (j.contains("friction")) d.friction = j["friction"].get<double>();  // [0, 1e6]: the schema
  if (j.contains("orientation_wxyz")) {
    const json& q = j["orientation_wxyz"];
    d.orientation = Quat(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(), q[3].get<double>());
    const double norm = d.orientation.norm();
    // Within 1e-9 of 1 make_body takes it as it is (and normalises it); within 1e-6 (a
    // quaternion written with 7 digits) it is normalised here first.
    if (!(std::abs(norm - 1.0) <= 1e-6)) {
      char text[64];
      std::snprintf(text, sizeof text, "%.9g", norm);
      fail(origin, at + "/orientation_wxyz",
           shown(q) + " is not allowed: its norm is " + text +
               "; give a unit quaternion [w, x, y, z] (norm within 1e-6 of 1; [1, 0, 0, 0] is no rotation)");
    }
    if (std::abs(norm - 1.0) > 1e-9) d.orientation.normalize();
  }
  if (j.contains("name")) body.name = j["name"];
  if (j.contains("color")) body.colour = colour_of(j["color"]);
  try {
    check.add_body(d);
  } catch (const std::invalid_argument& e) {
    const std::string key = key_of_body_error(e.what(), kind);
    fail(origin, key.empty() ? at : at + "/" + key,
         (key.empty() || !j.contains(key) ? std::string() : shown(j[key]) + " is not allowed: ") +
             e.what());
  }
  return body;
}

// The body a rod names by index or name (body_b: null is the world).
int body_ref(const std::string& origin, const json& j, const std::string& at,
             const std::vector<FileBody>& bodies) {
  if (j.is_null()) return kWorldBody;
  if (j.is_number()) {
    const double v = j.get<double>();
    if (v < 0 || v >= static_cast<double>(bodies.size()) || v != std::floor(v)) {
      fail(origin, at,
           shown(j) + ": no body has this index; the file has " + std::to_string(bodies.size()) +
               " bodies" + (bodies.empty() ? std::string() : ", indices 0.." + std::to_string(bodies.size() - 1)));
    }
    return static_cast<int>(v);
  }
  const std::string name = j;
  std::vector<std::string> names;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == name) return static_cast<int>(i);
    if (!bodies[i].name.empty()) names.push_back(bodies[i].name);
  }
  fail(origin, at,
       shown(j) + ": no body has this name" +
           (names.empty() ? std::string("; no body has a name (give \"name\" to a body, or use its index)")
                          : "; did you mean \"" + nearest_name(name, names) + "\"? (the names are: " + joined(names) + ")"));
}

}  // namespace

SceneFile parse_scene_file(std::string_view text, const std::string& origin) {
  const json doc = parse_json_text(text, origin);
  validate_against_schema(origin, doc);

  SceneFile file;
  file.origin = origin;
  file.name = doc.value("name", "");
  file.description = doc.value("description", "");
  file.seconds = doc.value("seconds", 10.0);
  file.plane_opacity = doc.value("plane_opacity", 1.0);
  if (doc.contains("world")) {
    for (const auto& [key, value] : doc["world"].items()) {
      const Parameter* p = find_parameter(key);
      if (p == nullptr || p->json_key != key) {
        fail(origin, "/world/" + key, "not a world parameter (the schema and the table differ)");
      }
      const ParameterValue v = parameter_value(*p, value);
      if (const std::optional<std::string> why = p->check(v)) {
        fail(origin, "/world/" + key, shown(value) + " is not allowed: " + *why);
      }
      p->set(file.world, v);
    }
  }
  World check(file.world);
  if (doc.contains("bodies")) {
    const json& bodies = doc["bodies"];
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      file.bodies.push_back(read_body(origin, bodies[i], i, check));
      const std::string& name = file.bodies.back().name;
      for (std::size_t k = 0; k + 1 < file.bodies.size() && !name.empty(); ++k) {
        if (file.bodies[k].name == name) {
          fail(origin, "/bodies/" + std::to_string(i) + "/name",
               shown(bodies[i]["name"]) + " is not allowed: it is already the name of body " +
                   std::to_string(k) + " (names must be unique: rods refer to bodies by them)");
        }
      }
    }
  }
  if (doc.contains("rods")) {
    const json& rods = doc["rods"];
    for (std::size_t i = 0; i < rods.size(); ++i) {
      const std::string at = "/rods/" + std::to_string(i);
      const json& r = rods[i];
      DistanceConstraint d;
      d.body_a = body_ref(origin, r["body_a"], at + "/body_a", file.bodies);
      d.body_b = body_ref(origin, r["body_b"], at + "/body_b", file.bodies);
      if (r.contains("point_a_m")) d.local_a = vec3_of(r["point_a_m"]);
      if (r.contains("point_b_m")) d.local_b = vec3_of(r["point_b_m"]);
      d.length = r["length_m"];
      if (r.contains("collide")) d.collide = r["collide"].get<bool>();
      if (d.body_a != kWorldBody && file.bodies[static_cast<std::size_t>(d.body_a)].def.is_static) {
        fail(origin, at + "/body_a",
             shown(r["body_a"]) + " is not allowed: body_a must be a movable body (a rod to a static "
             "body: give the static one as body_b, or null for a fixed point of the world)");
      }
      try {
        check.add_distance(d);
      } catch (const std::invalid_argument& e) {
        fail(origin, at, e.what());
      }
      file.rods.push_back(d);
    }
  }
  if (doc.contains("camera")) {
    const json& c = doc["camera"];
    CameraPreset preset;
    preset.eye = vec3_of(c["eye_m"]);
    preset.target = vec3_of(c["target_m"]);
    preset.fov_y_deg = c.value("fov_deg", 45.0);
    if (preset.eye == preset.target) {
      fail(origin, "/camera/target_m",
           shown(c["target_m"]) + " is not allowed: the camera looks from eye_m to target_m, which "
           "must differ");
    }
    file.camera = preset;
  }
  return file;
}

SceneFile read_scene_file(const std::filesystem::path& path) {
  const std::string origin = path.string();
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) {
    throw SceneFileError(origin + ": no such file (a scene file is a path ending in .json; "
                         "'cps list' shows the scenes and the example files)");
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw SceneFileError(origin + ": not a regular file (a folder?); give a scene file");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size > kMaxSceneFileBytes) {
    throw SceneFileError(origin + ": " + (ec ? "cannot read its size: " + ec.message()
                                             : std::to_string(size) + " bytes, more than the " +
                                                   std::to_string(kMaxSceneFileBytes) +
                                                   " bytes a scene file may have"));
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw SceneFileError(origin + ": cannot be read");
  return parse_scene_file(text.str(), origin);
}

namespace {

bool title_name(std::string_view n) {
  if (n.empty() || n.size() > 64 || n.front() == '.' || n.front() == '-') return false;
  for (const char c : n) {
    const auto u = static_cast<unsigned char>(c);
    if (!(std::isalnum(u) || c == '_' || c == '-' || c == '.' || u >= 0x80)) return false;
  }
  return true;
}

bool usable_stem(std::string_view n) {
  if (n.empty() || n.size() > 200 || n.front() == '.') return false;
  for (const char c : n) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f || c == '/' || c == '\\') return false;
  }
  return true;
}

}  // namespace

std::string unsafe_name_character(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    std::size_t length = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xe ? 3 : (b >> 3) == 0x1e ? 4 : 0;
    if (length == 0 || i + length > s.size()) return "invalid UTF-8 at byte " + std::to_string(i);
    char32_t c = length == 1 ? b : length == 2 ? (b & 0x1f) : length == 3 ? (b & 0x0f) : (b & 0x07);
    for (std::size_t k = 1; k < length; ++k) {
      const auto next = static_cast<unsigned char>(s[i + k]);
      if ((next >> 6) != 0x2) return "invalid UTF-8 at byte " + std::to_string(i + k);
      c = (c << 6) | (next & 0x3f);
    }
    const char* what = c < 0x20 || (c >= 0x7f && c <= 0x9f) ? "a control character"
                       : c == 0x061c || c == 0x200e || c == 0x200f || (c >= 0x202a && c <= 0x202e) ||
                               (c >= 0x2066 && c <= 0x2069)
                           ? "a bidirectional control"
                       : c == 0x2028 || c == 0x2029 ? "a line or paragraph separator"
                                                    : nullptr;
    if (what != nullptr) {
      char code[16];
      std::snprintf(code, sizeof code, "U+%04X", static_cast<unsigned>(c));
      return std::string(code) + " (" + what + ")";
    }
    i += length;
  }
  return "";
}

std::string scene_file_output_name(const SceneFile& file, const std::filesystem::path& path) {
  const std::string in_name = unsafe_name_character(file.name);
  if (!in_name.empty()) {
    throw SceneFileError(file.origin + ": /name: holds " + in_name + ", which no scene name may " +
                         "hold: a name must print as itself on one line");
  }
  const std::string stem = path.stem().string();
  const std::string name = title_name(file.name) ? file.name : usable_stem(stem) ? stem : std::string("scene");
  if (name == stem) {
    const std::string in_stem = unsafe_name_character(stem);
    if (!in_stem.empty()) {
      throw SceneFileError(file.origin + ": the file's name holds " + in_stem + ", which no name of " +
                           "cps's outputs may hold; rename the file, or give the scene a \"name\"");
    }
  }
  for (const std::string_view reserved : kReservedOutputNames) {
    if (name == reserved) {
      throw SceneFileError(file.origin + ": the scene's outputs would be named \"" + name +
                           "\", which is one of cps's own files (run, run.json, report, mass_ratio, plots); " +
                           (name == file.name ? "give another \"name\"" : "rename the file or give it a \"name\""));
    }
  }
  return name;
}

Scene scene_of(const SceneFile& file, std::string_view name) {
  Scene s;
  s.name = name;
  s.summary = file.description.empty() ? std::string_view(file.name) : std::string_view(file.description);
  s.default_seconds = file.seconds;
  s.world_def = [&file] { return file.world; };
  s.populate = [&file](World& world) {
    for (const FileBody& b : file.bodies) world.add_body(b.def);
    for (const DistanceConstraint& d : file.rods) world.add_distance(d);
  };
  s.make_metrics = [](const World& world) -> std::unique_ptr<Metrics> {
    return std::make_unique<FileSceneMetrics>(world);
  };
  s.plane_opacity = file.plane_opacity;
  s.camera = file.camera;
  s.bench = {.start_s = 0.0,
             .seconds = std::min(3.0, file.seconds),
             .reason = "a scene file: from its start, over up to 3 s of its run"};
  s.report.horizon_reason = "the scene file's \"seconds\"";
  return s;
}

namespace {

// The loaded files and their scenes, kept for the program's life.
struct Registry {
  std::mutex mutex;
  std::deque<SceneFile> files;
  std::deque<std::string> names;
  std::deque<std::string> output_names;
  std::deque<Scene> scenes;
  std::deque<std::vector<std::optional<Vec3>>> colours;  // by scene, as scenes

  const Scene* find(std::string_view name) {
    for (const Scene& s : scenes) {
      if (s.name == name) return &s;
    }
    return nullptr;
  }
  const Scene* add(SceneFile file, std::string name, std::string output_name) {
    files.push_back(std::move(file));
    names.push_back(std::move(name));
    output_names.push_back(std::move(output_name));
    scenes.push_back(scene_of(files.back(), names.back()));
    colours.emplace_back();
    for (const FileBody& b : files.back().bodies) colours.back().push_back(b.colour);
    return &scenes.back();
  }
};

Registry& registry() {
  static Registry r;
  return r;
}

const std::vector<std::string_view>& example_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> v;
    for (const assets::EmbeddedFile& f : assets::example_scenes) v.push_back(f.name);
    return v;
  }();
  return names;
}

}  // namespace

const Scene* load_scene_file(std::string_view path) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  if (const Scene* s = r.find(path)) return s;
  SceneFile file = read_scene_file(std::filesystem::path(path));
  std::string output = scene_file_output_name(file, std::filesystem::path(path));
  return r.add(std::move(file), std::string(path), std::move(output));
}

std::span<const std::string_view> example_scene_names() { return example_names(); }

std::string_view example_scene_text(std::string_view name) {
  for (const assets::EmbeddedFile& f : assets::example_scenes) {
    if (f.name == name) return f.text;
  }
  return {};
}

const Scene* find_example_scene(std::string_view name) {
  const std::string_view text = example_scene_text(name);
  if (text.empty()) return nullptr;
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  if (const Scene* s = r.find(name)) return s;
  return r.add(parse_scene_file(text, "assets/scenes/" + std::string(name) + ".json"), std::string(name),
               std::string(name));
}

std::string_view output_name(const Scene& scene) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (std::size_t i = 0; i < r.scenes.size(); ++i) {
    if (&r.scenes[i] == &scene) return r.output_names[i];
  }
  return scene.name;
}

std::span<const std::optional<Vec3>> body_colours(const Scene& scene) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (std::size_t i = 0; i < r.scenes.size(); ++i) {
    if (&r.scenes[i] == &scene) return r.colours[i];
  }
  return {};
}

bool is_file_scene(const Scene& scene) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (const Scene& s : r.scenes) {
    if (&s == &scene) return true;
  }
  return false;
}

std::vector<std::string> body_names(const Scene& scene) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  for (std::size_t i = 0; i < r.scenes.size(); ++i) {
    if (&r.scenes[i] != &scene) continue;
    for (const FileBody& b : r.files[i].bodies) names.push_back(b.name);
  }
  return names;
}

std::string_view scene_schema_text() { return assets::scene_schema; }

// ---- Metrics --------------------------------------------------------------------------------

double potential_energy(const World& world) {
  double e = 0.0;
  for (const Body& b : world.bodies()) {
    if (!b.is_static()) e -= b.mass * world.def().gravity.dot(b.x);
  }
  return e;
}

FileSceneMetrics::FileSceneMetrics(const World& world)
    : initial_kinetic_(kinetic_energy(world)), initial_potential_(potential_energy(world)) {
  observe(world);
}

void FileSceneMetrics::observe(const World& world) {
  kinetic_ = kinetic_energy(world);
  potential_ = potential_energy(world);
  if (!std::isfinite(kinetic_) || !std::isfinite(potential_)) nan_ = true;
  final_penetration_ = deepest_contact(world);
  max_penetration_ = std::max(max_penetration_, final_penetration_);
  max_rod_error_ = std::max(max_rod_error_, max_rod_error(world));
  const auto& bodies = world.bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].is_static()) continue;
    const double speed = bodies[i].velocity().norm();
    if (speed > max_speed_ || fastest_body_ < 0) {
      max_speed_ = speed;
      fastest_body_ = static_cast<int>(i);
    }
  }
}

nlohmann::json FileSceneMetrics::report() const {
  const double initial = initial_kinetic_ + initial_potential_;
  const double drift = kinetic_ + potential_ - initial;
  return {{"initial_kinetic_energy_J", initial_kinetic_},
          {"initial_potential_energy_J", initial_potential_},
          {"kinetic_energy_J", kinetic_},
          {"potential_energy_J", potential_},
          {"energy_drift_J", drift},
          {"relative_energy_drift", initial != 0.0 ? json(drift / std::abs(initial)) : json(nullptr)},
          {"max_penetration_m", max_penetration_},
          {"final_penetration_m", final_penetration_},
          {"max_rod_error_m", max_rod_error_},
          {"max_speed_mps", max_speed_},
          {"fastest_body", fastest_body_},
          {"nan", nan_}};
}

}  // namespace cps::scenes
