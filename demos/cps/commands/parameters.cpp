// `cps parameters`: the world parameter table (engine/src/parameters.cpp) as Markdown, JSON, the
// scene schema's world section, or tab-separated rows for scripts. The schema's world section
// (assets/schemas/scene.schema.json) and the option table of docs/commands.md are this output;
// tests/cli/test_cli_parameters.cpp fails when they differ, and scripts/update-parameters.sh rewrites
// them.
#include "command.h"

#include "cps/parameters.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>

namespace cps::cli {
namespace {

using nlohmann::json;

std::string_view type_name(ParameterType t) {
  switch (t) {
    case ParameterType::real: return "real";
    case ParameterType::integer: return "integer";
    case ParameterType::boolean: return "boolean";
    case ParameterType::vector3: return "vector3";
    case ParameterType::choice: return "choice";
  }
  return "";
}

// A parameter's value as JSON: a number, a bool, [x, y, z] or a choice's name.
json value_json(const Parameter& p, const ParameterValue& v) {
  switch (p.type) {
    case ParameterType::real: return std::get<double>(v);
    case ParameterType::integer: return std::get<int>(v);
    case ParameterType::boolean: return std::get<bool>(v);
    case ParameterType::vector3: {
      const Vec3& x = std::get<Vec3>(v);
      return json::array({x.x(), x.y(), x.z()});
    }
    case ParameterType::choice: return std::string(p.choice_name(std::get<int>(v)));
  }
  return nullptr;
}

// A bound as JSON: null for an unbounded side (JSON has no infinity).
json bound_json(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::string default_text(const Parameter& p) {
  const ParameterValue v = p.get(WorldDef{});
  if (p.type == ParameterType::vector3) {
    const Vec3& x = std::get<Vec3>(v);
    return shortest_decimal(x.x()) + ", " + shortest_decimal(x.y()) + ", " +
           shortest_decimal(x.z());
  }
  return p.format(v);
}

// Which settings of the solve a push method reads (PushTraits: reads, and solves_system for the
// assembly and the row precision, which only the solve of A lambda = b uses), by parameter name.
// A setting it does not read leaves its runs bit for bit the same.
json push_reads_json(const PushTraits& traits) {
  return {{"solver", traits.reads.solver},
          {"assembly", traits.solves_system},
          {"row_precision", traits.solves_system},
          {"friction_model", traits.reads.friction_model},
          {"warm_start", traits.reads.warm_start}};
}

// Every parameter with its name, flag, JSON key, unit, type, range, default, help and choices
// (a push method's with the settings it reads).
json table_json() {
  json out = json::array();
  for (const Parameter& p : world_parameters()) {
    json row = {{"name", p.name},
                {"flag", p.flag.empty() ? json(nullptr) : json("--" + std::string(p.flag))},
                {"json_key", p.json_key},
                {"unit", p.unit},
                {"type", type_name(p.type)},
                {"allowed", p.allowed()},
                {"default", value_json(p, p.get(WorldDef{}))},
                {"help", p.help},
                {"title", p.label()}};
    if (p.type == ParameterType::real || p.type == ParameterType::integer ||
        p.type == ParameterType::vector3) {
      row["min"] = bound_json(p.min);
      row["max"] = bound_json(p.max);
    }
    if (p.type == ParameterType::real) row["min_exclusive"] = p.min_exclusive;
    if (p.type == ParameterType::choice) {
      json choices = json::array();
      for (const Choice& c : p.choices) {
        json choice = {{"name", c.name},
                       {"source", c.source},
                       {"title", c.title},
                       {"in_paper", c.in_paper}};
        if (c.push != nullptr) choice["reads"] = push_reads_json(*c.push);
        choices.push_back(choice);
      }
      row["choices"] = choices;
    }
    out.push_back(row);
  }
  return out;
}

// The scene schema's "world" definition: one property per JSON key, its JSON type (or the
// choices' names), and a description of what is allowed, the default and the help.
json world_schema() {
  json properties = json::object();
  for (const Parameter& p : world_parameters()) {
    json node;
    switch (p.type) {
      case ParameterType::real: node["type"] = "number"; break;
      case ParameterType::integer: node["type"] = "integer"; break;
      case ParameterType::boolean: node["type"] = "boolean"; break;
      case ParameterType::vector3:
        node = {{"type", "array"}, {"minItems", 3}, {"maxItems", 3},
                {"items", {{"type", "number"}}}};
        break;
      case ParameterType::choice: {
        json names = json::array();
        for (const Choice& c : p.choices) names.push_back(c.name);
        node["enum"] = names;
        break;
      }
    }
    // What is allowed first: scene file errors quote the description after "is not allowed: ".
    node["description"] = p.allowed() + "; default " + default_text(p) + "; " + std::string(p.help);
    properties[std::string(p.json_key)] = node;
  }
  return {{"type", "object"},
          {"additionalProperties", false},
          {"description",
           "world parameters by the JSON key of the parameter table (`cps parameters`); an "
           "omitted key takes the table's default"},
          {"properties", properties}};
}

// Markdown table cell text: '|' escaped.
std::string cell(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

std::string table_markdown() {
  std::string md =
      "| option | JSON key | meaning | unit | allowed | default |\n"
      "|---|---|---|---|---|---|\n";
  for (const Parameter& p : world_parameters()) {
    const std::string flag =
        p.flag.empty() ? "(scene files only)" : "`--" + std::string(p.flag) + "`";
    md += "| " + flag + " | `" + std::string(p.json_key) + "` | " + cell(p.help) + " | " +
          (p.unit.empty() ? "" : std::string(p.unit)) + " | " + cell(p.allowed()) + " | " +
          cell(default_text(p)) + " |\n";
  }
  return md;
}

// One line per parameter with a flag: flag, type, min, max, min_exclusive (0/1), unit; tab
// separated, for scripts (scripts/bad-input-sweep.sh reads the value kinds from it).
std::string table_tsv() {
  std::string out;
  for (const Parameter& p : world_parameters()) {
    if (p.flag.empty()) continue;
    out += "--" + std::string(p.flag) + "\t" + std::string(type_name(p.type)) + "\t" +
           shortest_decimal(p.min) + "\t" + shortest_decimal(p.max) + "\t" +
           (p.min_exclusive ? "1" : "0") + "\t" + std::string(p.unit) + "\n";
  }
  return out;
}

}  // namespace

Command add_parameters(CLI::App& app) {
  auto format = std::make_shared<std::string>("markdown");
  CLI::App* sub = app.add_subcommand(
      "parameters", "print the world parameter table: every parameter's option, JSON key, unit, "
                    "allowed values and default");
  sub->add_option("--format", *format,
                  "markdown: a table; json: an array of parameters; schema: the scene file "
                  "schema's world section; tsv: flag, type, min, max, min_exclusive, unit per line")
      ->check(CLI::IsMember({"markdown", "json", "schema", "tsv"}))
      ->capture_default_str();
  return {sub, [format] {
            if (*format == "json") {
              std::cout << table_json().dump(2) << "\n";
            } else if (*format == "schema") {
              std::cout << world_schema().dump(2) << "\n";
            } else if (*format == "tsv") {
              std::cout << table_tsv();
            } else {
              std::cout << table_markdown();
            }
            return 0;
          }};
}

}  // namespace cps::cli
