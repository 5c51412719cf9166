// The error reporting of scene files: messages naming the file, the JSON pointer, the value and
// what is allowed; the syntax pass (line:column) and the schema pass (valijson) of scene_file.h,
// and nearest_name (scene.h) for the "did you mean" of a misspelt key or name.
#include "scene_file_errors.h"

#include "scene_file.h"

#include "cps_scene_assets.h"

#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>

#include <algorithm>
#include <cctype>
#include <map>
#include <memory>
#include <unordered_map>
#include <unordered_set>

namespace cps::scenes::detail {
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

}  // namespace

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

namespace {

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

}  // namespace

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

namespace {

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
  std::size_t index = 0;                     // array: the element being read
  std::string key;                           // object: the member being read
  std::unordered_set<std::string> keys;      // object: the keys read so far
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

// The largest number of items the schema allows the top-level array `key` ("bodies", "rods").
std::size_t schema_max_items(const char* key) {
  return schema_json().at("properties").at(key).at("maxItems").get<std::size_t>();
}

// The checking pass of parse_json_text, as nlohmann's SAX interface: it builds nothing, keeps
// one frame per open object or array, and throws SceneFileError at the first thing refused, so
// the cost is linear in the text and a refusal comes as soon as the text shows it.
class CheckingSax {
 public:
  using number_integer_t = json::number_integer_t;
  using number_unsigned_t = json::number_unsigned_t;
  using number_float_t = json::number_float_t;
  using string_t = json::string_t;
  using binary_t = json::binary_t;

  CheckingSax(std::string_view text, const std::string& origin) : text_(text), origin_(origin) {}

  bool null() { return value(); }
  bool boolean(bool) { return value(); }
  bool number_integer(number_integer_t) { return value(); }
  bool number_unsigned(number_unsigned_t) { return value(); }
  bool number_float(number_float_t, const string_t&) { return value(); }
  bool string(string_t&) { return value(); }
  bool binary(binary_t&) { return value(); }
  bool start_object(std::size_t) { return open(true); }
  bool start_array(std::size_t) { return open(false); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(string_t& key) {
    ParseFrame& f = frames_.back();
    f.key = key;
    const std::size_t seen = key_count_[key]++;
    if (!f.keys.insert(key).second) {
      const std::size_t at = key_position(text_, key, seen);
      throw SceneFileError(origin_ + ":" + (at == std::string_view::npos ? "" : line_column(text_, at) + ":") +
                           " " + pointer_at(frames_) + ": the key \"" + excerpt(key) +
                           "\" a second time in one object; give each key once");
    }
    return true;
  }

  // position: the bytes read when the parser stopped, counted from 1.
  // last_token: the token read last (a number that overflowed ends at position).
  bool parse_error(std::size_t position, const std::string& last_token,
                   const nlohmann::detail::exception& e) {
    const std::size_t at = position == 0 ? 0 : position - 1;
    std::string why = e.what();
    if (dynamic_cast<const json::out_of_range*>(&e) != nullptr) {
      const std::size_t start = position >= last_token.size() ? position - last_token.size() : 0;
      // "number overflow parsing '1e400'": the number as written.
      const std::size_t open = why.find('\'');
      const std::size_t close = why.rfind('\'');
      const std::string number =
          open != std::string::npos && close > open ? why.substr(open + 1, close - open - 1) : "";
      throw SceneFileError(origin_ + ":" + line_column(text_, start) + ": " + pointer_at(frames_) +
                           ": the number " + (number.empty() ? "" : excerpt(number) + " ") +
                           "is out of the range of a double (at most about 1.8e308 in size)");
    }
    const std::size_t cut = why.find("syntax error");
    if (cut != std::string::npos) why = why.substr(cut);
    throw SceneFileError(origin_ + ":" + line_column(text_, at) +
                         ": not valid JSON (comments are allowed): " + why);
  }

 private:
  bool open(bool object) {
    if (frames_.size() >= kMaxSceneFileDepth) {
      throw SceneFileError(origin_ + ": " + pointer_at(frames_) + ": nested deeper than " +
                           std::to_string(kMaxSceneFileDepth) +
                           " objects and arrays; a scene file needs 4");
    }
    frames_.push_back({object, 0, {}, {}});
    return true;
  }

  bool close() {
    frames_.pop_back();
    return value();
  }

  // A value ended: the next element of an enclosing array, counted against the schema's
  // maxItems for the top-level "bodies" and "rods".
  bool value() {
    if (frames_.empty() || frames_.back().object) return true;
    ParseFrame& f = frames_.back();
    ++f.index;
    if (frames_.size() == 2 && frames_.front().object) {
      const std::string& key = frames_.front().key;
      if (key == "bodies" || key == "rods") {
        static const std::size_t max_bodies = schema_max_items("bodies");
        static const std::size_t max_rods = schema_max_items("rods");
        const std::size_t most = key == "bodies" ? max_bodies : max_rods;
        if (f.index > most) {
          throw SceneFileError(origin_ + ": /" + key + ": more than " + std::to_string(most) + " " +
                               key + " (the most a scene file may hold); refused at /" + key + "/" +
                               std::to_string(most) + ", before the rest was read");
        }
      }
    }
    return true;
  }

  std::string_view text_;
  const std::string& origin_;
  std::vector<ParseFrame> frames_;
  std::unordered_map<std::string, std::size_t> key_count_;  // keys seen so far, for their position
};

}  // namespace

// Parses the JSON text of a scene file in two linear passes: the checking pass (CheckingSax)
// refuses, with the file, line:column and pointer: nesting deeper than kMaxSceneFileDepth, a key
// twice in one object, more "bodies" or "rods" than the schema allows, a number out of the range
// of a double, a NUL byte (the parser would stop there and take what follows for the end),
// anything after the document, and any syntax error; then the document is built.
json parse_json_text(std::string_view text, const std::string& origin) {
  const std::size_t nul = text.find('\0');
  if (nul != std::string_view::npos) {
    throw SceneFileError(origin + ":" + line_column(text, nul) +
                         ": a NUL byte: a scene file is JSON text, and nothing may follow the "
                         "document");
  }
  CheckingSax check(text, origin);
  json::sax_parse(text, &check, json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/true);
  // nlohmann's parser with a callback is quadratic in an array's objects; without one it is
  // linear, and the text is known good.
  return json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
}

}  // namespace cps::scenes::detail

