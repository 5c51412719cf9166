#include "scene_file.h"

#include "cps_scene_assets.h"

#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>

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

// ---- Messages ------------------------------------------------------------------------------

// A JSON pointer from its reference tokens (RFC 6901: '~' as ~0, '/' as ~1).
std::string pointer_of(const std::vector<std::string>& tokens) {
  std::string p;
  for (const std::string& t : tokens) {
    p += '/';
    for (const char c : t) {
      if (c == '~') {
        p += "~0";
      } else if (c == '/') {
        p += "~1";
      } else {
        p += c;
      }
    }
  }
  return p;
}

// A value as it appears in a message: its JSON text, cut at 60 characters.
std::string shown(const json& v) {
  std::string text = v.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

[[noreturn]] void fail(const std::string& origin, const std::string& pointer,
                       const std::string& why) {
  throw SceneFileError(origin + ": " + (pointer.empty() ? std::string("(top level)") : pointer) +
                       ": " + why);
}

std::string joined(const std::vector<std::string>& words) {
  std::string s;
  for (const std::string& w : words) s += (s.empty() ? "" : ", ") + w;
  return s;
}

// ---- The schema ------------------------------------------------------------------------------

const json& schema_json() {
  static const json schema = json::parse(assets::scene_schema);
  return schema;
}

// The schema node `node` refers to: follows "$ref": "#/definitions/NAME".
const json& resolved(const json& node) {
  const json* n = &node;
  while (n->is_object() && n->contains("$ref")) {
    const std::string ref = n->at("$ref").get<std::string>();
    n = &schema_json().at(json::json_pointer(ref.substr(1)));
  }
  return *n;
}

// What a schema node allows, in words: its "description" (the referring node's first).
std::string allowed_by(const json& node) {
  if (node.is_object() && node.contains("description")) return node["description"];
  const json& r = resolved(node);
  if (r.is_object() && r.contains("description")) return r["description"];
  return "see assets/schemas/scene.schema.json";
}

std::vector<std::string> property_names(const json& schema_node) {
  std::vector<std::string> names;
  const json& r = resolved(schema_node);
  if (r.is_object() && r.contains("properties")) {
    for (const auto& [key, value] : r["properties"].items()) {
      if (key != "$schema") names.push_back(key);
    }
  }
  return names;
}

// The keys an object of this schema node must have, given its value: "required", and the
// "then": {"required"} of each "allOf" item whose "if" (a "const" of one property) holds.
std::vector<std::string> required_keys(const json& schema_node, const json& value) {
  std::vector<std::string> keys;
  const json& r = resolved(schema_node);
  if (r.contains("required")) {
    for (const json& k : r["required"]) keys.push_back(k);
  }
  if (r.contains("allOf")) {
    for (const json& rule : r["allOf"]) {
      if (!rule.contains("if") || !rule.contains("then")) continue;
      bool holds = true;
      for (const auto& [key, condition] : rule["if"]["properties"].items()) {
        holds = holds && value.contains(key) && value[key] == condition["const"];
      }
      if (holds && rule["then"].contains("required")) {
        for (const json& k : rule["then"]["required"]) keys.push_back(k);
      }
    }
  }
  return keys;
}

// Explains why the value at `tokens` is refused, walking the schema along the pointer: an
// unknown key on the way (with the nearest known one), a missing required key, or the value and
// what its schema allows. Always throws.
[[noreturn]] void explain(const std::string& origin, const json& doc,
                          const std::vector<std::string>& tokens) {
  const json* value = &doc;
  const json* node = &schema_json();
  std::vector<std::string> path;
  for (const std::string& t : tokens) {
    const json& r = resolved(*node);
    if (value->is_object()) {
      const std::vector<std::string> known = property_names(*node);
      if (std::find(known.begin(), known.end(), t) == known.end()) break;  // reported below
      node = &r["properties"][t];
      value = &(*value)[t];
    } else if (value->is_array() && r.contains("items")) {
      std::size_t index = 0;
      try {
        index = static_cast<std::size_t>(std::stoul(t));
      } catch (const std::exception&) {
        break;
      }
      if (index >= value->size()) break;
      node = &r["items"];
      value = &(*value)[index];
    } else {
      break;
    }
    path.push_back(t);
  }
  const std::string pointer = pointer_of(path);
  const json& r = resolved(*node);
  if (value->is_object() && r.is_object() && r.value("type", "") == "object") {
    const std::vector<std::string> known = property_names(*node);
    for (const auto& [key, v] : value->items()) {
      if (key == "$schema" || std::find(known.begin(), known.end(), key) != known.end()) continue;
      std::vector<std::string> where = path;
      where.push_back(key);
      fail(origin, pointer_of(where),
           "unknown key \"" + key + "\"; did you mean \"" + nearest_name(key, known) +
               "\"? (the keys allowed here are: " + joined(known) + ")");
    }
    for (const std::string& key : required_keys(*node, *value)) {
      if (value->contains(key)) continue;
      fail(origin, pointer,
           "the key \"" + key + "\" is missing: " + allowed_by(r["properties"][key]));
    }
  }
  fail(origin, pointer, shown(*value) + " is not allowed: " + allowed_by(*node));
}

// The context valijson gives an error ("<root>", "[bodies]", "[3]", ...) as pointer tokens.
std::vector<std::string> tokens_of(const std::vector<std::string>& context) {
  std::vector<std::string> tokens;
  for (const std::string& c : context) {
    if (c.size() >= 2 && c.front() == '[' && c.back() == ']') tokens.push_back(c.substr(1, c.size() - 2));
  }
  return tokens;
}

void validate_against_schema(const std::string& origin, const json& doc) {
  static const std::unique_ptr<valijson::Schema> schema = [] {
    auto s = std::make_unique<valijson::Schema>();
    valijson::SchemaParser parser;
    valijson::adapters::NlohmannJsonAdapter adapter(schema_json());
    parser.populateSchema(adapter, *s);
    return s;
  }();
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(doc);
  if (validator.validate(*schema, target, &results)) return;
  // The deepest error is the most precise one (the others are its enclosing objects').
  std::vector<std::string> deepest;
  bool first = true;
  for (const valijson::ValidationResults::Error& e : results) {
    std::vector<std::string> t = tokens_of(e.context);
    if (first || t.size() > deepest.size()) deepest = std::move(t);
    first = false;
  }
  explain(origin, doc, deepest);
}

// ---- Reading values (after the schema: types and sizes are right) ---------------------------

Vec3 vec3_of(const json& j) { return Vec3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>()); }

json json_of(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

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

json parameter_json(const Parameter& p, const ParameterValue& v) {
  switch (p.type) {
    case ParameterType::real:
      return std::get<double>(v);
    case ParameterType::integer:
      return std::get<int>(v);
    case ParameterType::boolean:
      return std::get<bool>(v);
    case ParameterType::vector3:
      return json_of(std::get<Vec3>(v));
    case ParameterType::choice:
      return std::string(p.choice_name(std::get<int>(v)));
  }
  return nullptr;
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

// Line and column (from 1) of byte `at` of `text`.
std::string line_column(std::string_view text, std::size_t at) {
  at = std::min(at, text.size());
  std::size_t line = 1;
  std::size_t column = 1;
  for (std::size_t i = 0; i < at; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

// Where the parse is: one frame per open object or array, for the pointer of a message and the
// keys an object already has.
struct ParseFrame {
  bool object = false;
  std::size_t index = 0;             // array: the element being read
  std::string key;                   // object: the member being read
  std::vector<std::string> keys;     // object: the keys read so far
};

// Text for a message, at most 120 characters: the start and the end of a longer one.
std::string excerpt(const std::string& text) {
  if (text.size() <= 120) return text;
  return text.substr(0, 40) + "..." + text.substr(text.size() - 77);
}

std::string pointer_at(const std::vector<ParseFrame>& frames) {
  std::vector<std::string> tokens;
  for (const ParseFrame& f : frames) tokens.push_back(f.object ? f.key : std::to_string(f.index));
  return excerpt(pointer_of(tokens));
}

// The byte where the n-th (from 0) key `key` of the text starts: an unescaped "key" followed by
// ':' (after white space); npos if not found (a key written with escapes).
std::size_t key_position(std::string_view text, const std::string& key, std::size_t n) {
  const std::string quoted = "\"" + key + "\"";
  for (std::size_t at = text.find(quoted); at != std::string_view::npos;
       at = text.find(quoted, at + 1)) {
    if (at > 0 && text[at - 1] == '\\') continue;
    std::size_t after = at + quoted.size();
    while (after < text.size() && std::isspace(static_cast<unsigned char>(text[after]))) ++after;
    if (after < text.size() && text[after] == ':' && n-- == 0) return at;
  }
  return std::string_view::npos;
}

// Parses the JSON text of a scene file: comments allowed; refused, with the file, line:column
// and pointer: nesting deeper than kMaxSceneFileDepth, a key twice in one object, a number out
// of the range of a double, a NUL byte (the parser would stop there and take what follows for
// the end), anything after the document, and any syntax error.
json parse_json_text(std::string_view text, const std::string& origin) {
  const std::size_t nul = text.find('\0');
  if (nul != std::string_view::npos) {
    throw SceneFileError(origin + ":" + line_column(text, nul) +
                         ": a NUL byte: a scene file is JSON text, and nothing may follow the "
                         "document");
  }
  std::vector<ParseFrame> frames;
  std::map<std::string, std::size_t> key_count;  // keys seen so far, for their position
  const json::parser_callback_t track = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (frames.size() >= kMaxSceneFileDepth) {
          throw SceneFileError(origin + ": " + pointer_at(frames) + ": nested deeper than " +
                               std::to_string(kMaxSceneFileDepth) +
                               " objects and arrays; a scene file needs 4");
        }
        frames.push_back({event == json::parse_event_t::object_start, 0, {}, {}});
        break;
      case json::parse_event_t::key: {
        ParseFrame& f = frames.back();
        f.key = parsed.get<std::string>();
        const std::size_t seen = key_count[f.key]++;
        if (std::find(f.keys.begin(), f.keys.end(), f.key) != f.keys.end()) {
          const std::size_t at = key_position(text, f.key, seen);
          throw SceneFileError(origin + ":" +
                               (at == std::string_view::npos ? "" : line_column(text, at) + ":") +
                               " " + pointer_at(frames) + ": the key \"" + excerpt(f.key) +
                               "\" a second time in one object; give each key once");
        }
        f.keys.push_back(f.key);
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames.pop_back();
        if (!frames.empty() && !frames.back().object) ++frames.back().index;
        break;
      case json::parse_event_t::value:
        if (!frames.empty() && !frames.back().object) ++frames.back().index;
        break;
    }
    return true;
  };
  try {
    return json::parse(text, track, true, /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    // e.byte: the byte where parsing stopped, counted from 1.
    std::string why = e.what();
    const std::size_t cut = why.find("syntax error");
    if (cut != std::string::npos) why = why.substr(cut);
    throw SceneFileError(origin + ":" + line_column(text, e.byte == 0 ? 0 : e.byte - 1) +
                         ": not valid JSON (comments are allowed): " + why);
  } catch (const json::out_of_range& e) {
    // "number overflow parsing '1e400'": the number as written, and where it first appears.
    const std::string why = e.what();
    const std::size_t open = why.find('\'');
    const std::size_t close = why.rfind('\'');
    const std::string number =
        open != std::string::npos && close > open ? why.substr(open + 1, close - open - 1) : "";
    const std::size_t at = number.empty() ? std::string_view::npos : text.find(number);
    throw SceneFileError(origin + ":" +
                         (at == std::string_view::npos ? "" : line_column(text, at) + ":") + " " +
                         pointer_at(frames) + ": the number " + (number.empty() ? "" : number + " ") +
                         "is out of the range of a double (at most about 1.8e308 in size)");
  }
}

}  // namespace

// Levenshtein distance, for "did you mean" suggestions.
namespace {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string nearest_name(std::string_view word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::string::npos;
  for (const std::string& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

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

std::string scene_file_output_name(const SceneFile& file, const std::filesystem::path& path) {
  if (title_name(file.name)) return file.name;
  const std::string stem = path.stem().string();
  return usable_stem(stem) ? stem : std::string("scene");
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

// ---- Writing a world as a scene file --------------------------------------------------------

namespace {

// The value next to x by `steps` units in the last place (steps may be negative).
double ulps_away(double x, int steps) {
  for (; steps > 0; --steps) x = std::nextafter(x, kInfinity);
  for (; steps < 0; ++steps) x = std::nextafter(x, -kInfinity);
  return x;
}

// A velocity v (m/s) with mass * v == p in every bit, near p / mass; p / mass if none is found.
Vec3 velocity_for(const Body& b) {
  Vec3 v;
  for (int k = 0; k < 3; ++k) {
    const double guess = b.p[k] / b.mass;
    v[k] = guess;
    for (const int s : {0, 1, -1, 2, -2, 3, -3}) {
      if (b.mass * ulps_away(guess, s) == b.p[k]) {
        v[k] = ulps_away(guess, s);
        break;
      }
    }
  }
  return v;
}

// An angular velocity w (rad/s) from which make_body rebuilds l = R I R^T w in every bit, near
// I^-1 l; I^-1 l if none is found within 2 units in the last place per component.
Vec3 angular_velocity_for(const Body& b) {
  const Vec3 guess = b.angular_velocity();
  if (b.l == Vec3::Zero()) return Vec3::Zero();
  const Mat3 R = b.rotation();
  const Mat3 I = shape_inertia(b.shape, b.mass);
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      for (int k = -2; k <= 2; ++k) {
        const Vec3 w(ulps_away(guess.x(), i), ulps_away(guess.y(), j), ulps_away(guess.z(), k));
        if (R * I * R.transpose() * w == b.l) return w;
      }
    }
  }
  return guess;
}

// A quaternion q with q.normalized() == o in every bit (make_body normalises what it is given).
Quat orientation_for(const Quat& o) {
  for (int a = -1; a <= 1; ++a) {
    for (int b = -1; b <= 1; ++b) {
      for (int c = -1; c <= 1; ++c) {
        for (int d = -1; d <= 1; ++d) {
          const Quat q(ulps_away(o.w(), a), ulps_away(o.x(), b), ulps_away(o.y(), c), ulps_away(o.z(), d));
          if (q.normalized().coeffs() == o.coeffs()) return q;
        }
      }
    }
  }
  return o;
}

// A normal n with n / |n| == `unit` in every bit (Shape::plane normalises what it is given).
Vec3 normal_for(const Vec3& unit) {
  for (int a = -1; a <= 1; ++a) {
    for (int b = -1; b <= 1; ++b) {
      for (int c = -1; c <= 1; ++c) {
        const Vec3 n(ulps_away(unit.x(), a), ulps_away(unit.y(), b), ulps_away(unit.z(), c));
        if (n / n.norm() == unit) return n;
      }
    }
  }
  return unit;
}

std::string hex_colour(const Vec3& linear) {
  char text[8];
  int c[3];
  for (int k = 0; k < 3; ++k) {
    const double l = std::clamp(linear[k], 0.0, 1.0);
    const double srgb = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
    c[k] = static_cast<int>(std::lround(srgb * 255.0));
  }
  std::snprintf(text, sizeof text, "#%02x%02x%02x", c[0], c[1], c[2]);
  return text;
}

}  // namespace

nlohmann::json scene_file_json(const Scene& scene, const World& as_built) {
  json j = json::object();
  j["$schema"] = "https://github.com/cps/assets/schemas/scene.schema.json";
  j["name"] = std::string(scene.name);
  j["description"] = std::string(scene.summary);
  j["seconds"] = scene.default_seconds;
  if (scene.plane_opacity != 1.0) j["plane_opacity"] = scene.plane_opacity;
  json world = json::object();
  for (const Parameter& p : world_parameters()) {
    world[std::string(p.json_key)] = parameter_json(p, p.get(as_built.def()));
  }
  j["world"] = world;
  json bodies = json::array();
  const auto& all = as_built.bodies();
  const std::span<const std::optional<Vec3>> colours = body_colours(scene);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Body& b = all[i];
    json body = json::object();
    switch (b.shape.kind) {
      case ShapeKind::box:
        body["shape"] = "box";
        body["half_extents_m"] = json_of(b.shape.half_extents);
        break;
      case ShapeKind::sphere:
        body["shape"] = "sphere";
        body["radius_m"] = b.shape.radius;
        break;
      case ShapeKind::plane:
        body["shape"] = "plane";
        body["normal"] = json_of(normal_for(b.shape.normal));
        body["offset_m"] = b.shape.offset;
        break;
    }
    if (b.is_static()) {
      if (b.shape.kind != ShapeKind::plane) body["static"] = true;
    } else {
      body["mass_kg"] = b.mass;
    }
    body["position_m"] = json_of(b.x);
    const Quat q = orientation_for(b.o);
    if (!(q.w() == 1.0 && q.vec() == Vec3::Zero())) body["orientation_wxyz"] = {q.w(), q.x(), q.y(), q.z()};
    if (!b.is_static()) {
      const Vec3 v = velocity_for(b);
      const Vec3 w = angular_velocity_for(b);
      if (v != Vec3::Zero()) body["velocity_mps"] = json_of(v);
      if (w != Vec3::Zero()) body["angular_velocity_radps"] = json_of(w);
    }
    if (i < colours.size() && colours[i]) body["color"] = hex_colour(*colours[i]);
    bodies.push_back(body);
  }
  j["bodies"] = bodies;
  if (!as_built.distances().empty()) {
    json rods = json::array();
    for (const DistanceConstraint& d : as_built.distances()) {
      rods.push_back({{"body_a", d.body_a},
                      {"point_a_m", json_of(d.local_a)},
                      {"body_b", d.body_b == kWorldBody ? json(nullptr) : json(d.body_b)},
                      {"point_b_m", json_of(d.local_b)},
                      {"length_m", d.length}});
    }
    j["rods"] = rods;
  }
  if (scene.camera) {
    j["camera"] = {{"eye_m", json_of(scene.camera->eye)},
                   {"target_m", json_of(scene.camera->target)},
                   {"fov_deg", scene.camera->fov_y_deg}};
  }
  return j;
}

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
