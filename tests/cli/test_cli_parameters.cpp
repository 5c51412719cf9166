// `cps parameters` against the table it prints, and the two copies of the table outside the
// code: the scene schema's world section (assets/schemas/scene.schema.json) and the option table
// of docs/commands.md. Either fails when someone edits the table and not them (or the other way
// round); scripts/update-parameters.sh rewrites both from `cps parameters`.
#include "cli_support.h"

#include "cps/parameters.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>

namespace {

using cli_test::fresh_dir;
using cli_test::run_cps;
using cli_test::slurp;
using nlohmann::json;

const std::filesystem::path kSource = CPS_SOURCE_DIR;

// The text between the marker lines "<!-- BEGIN name -->" and "<!-- END name -->" of `text`
// (without the markers' lines), or "" when they are missing.
std::string between_markers(const std::string& text, const std::string& name) {
  const std::string begin = "<!-- BEGIN " + name + " -->\n";
  const std::string end = "<!-- END " + name + " -->";
  const std::size_t b = text.find(begin);
  if (b == std::string::npos) return "";
  const std::size_t e = text.find(end, b);
  if (e == std::string::npos) return "";
  return text.substr(b + begin.size(), e - b - begin.size());
}

}  // namespace

TEST_CASE("cps parameters --format json lists every world parameter of the table with its default",
          "[cli][parameters]") {
  const auto dir = fresh_dir("cps_parameters_json");
  const cli_test::Result r = run_cps("parameters --format json", dir);
  REQUIRE(r.exit_code == 0);
  const json table = json::parse(r.out);
  const auto params = cps::world_parameters();
  REQUIRE(table.size() == params.size());
  const cps::WorldDef defaults;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const cps::Parameter& p = params[i];
    const json& row = table[i];
    CHECK(row.at("name") == std::string(p.name));
    CHECK(row.at("json_key") == std::string(p.json_key));
    CHECK(row.at("unit") == std::string(p.unit));
    // The default printed reads back, through the table's own parser, as WorldDef's default.
    const json& d = row.at("default");
    std::string text;
    if (d.is_array()) {
      text = d[0].dump() + "," + d[1].dump() + "," + d[2].dump();
    } else if (d.is_string()) {
      text = d.get<std::string>();
    } else {
      text = d.dump();
    }
    CHECK(p.parse(text) == p.get(defaults));
  }
  // Which push methods are the paper's is the table's own field, not a label.
  const json* push = nullptr;
  for (const json& row : table) {
    if (row.at("name") == "push") push = &row;
  }
  REQUIRE(push != nullptr);
  int in_paper = 0;
  for (const json& c : push->at("choices")) in_paper += c.at("in_paper").get<bool>() ? 1 : 0;
  CHECK(in_paper == 2);  // Sec. 5.3 and Sec. 8.1
  // Each push method's `reads` is its row of the engine's table (PushTraits), by parameter name.
  for (const json& c : push->at("choices")) {
    CAPTURE(c.dump());
    const cps::Choice* choice = cps::parameter("push").find_choice(c.at("name").get<std::string>());
    REQUIRE(choice != nullptr);
    REQUIRE(choice->push != nullptr);
    const cps::PushTraits& traits = *choice->push;
    const json& reads = c.at("reads");
    CHECK(reads.size() == 5);
    CHECK(reads.at("solver").get<bool>() == traits.reads.solver);
    CHECK(reads.at("assembly").get<bool>() == traits.solves_system);
    CHECK(reads.at("row_precision").get<bool>() == traits.solves_system);
    CHECK(reads.at("friction_model").get<bool>() == traits.reads.friction_model);
    CHECK(reads.at("warm_start").get<bool>() == traits.reads.warm_start);
    for (const auto& [name, read] : reads.items()) CHECK(cps::find_parameter(name) != nullptr);
  }
  // No other parameter's choices carry one.
  for (const json& row : table) {
    if (row.at("name") == "push" || !row.contains("choices")) continue;
    for (const json& c : row.at("choices")) CHECK(!c.contains("reads"));
  }
}

TEST_CASE("the scene schema's world section is the parameter table's", "[cli][parameters]") {
  const auto dir = fresh_dir("cps_parameters_schema");
  const cli_test::Result r = run_cps("parameters --format schema", dir);
  REQUIRE(r.exit_code == 0);
  const json generated = json::parse(r.out);
  const json schema = json::parse(slurp(kSource / "assets/schemas/scene.schema.json"));
  const json& world = schema.at("definitions").at("world");
  INFO("assets/schemas/scene.schema.json differs from `cps parameters --format schema`: run "
       "scripts/update-parameters.sh");
  CHECK(world == generated);
  // Every parameter is in it under its JSON key.
  for (const cps::Parameter& p : cps::world_parameters()) {
    CHECK(world.at("properties").contains(std::string(p.json_key)));
  }
}

TEST_CASE("the option table of docs/commands.md is the parameter table's", "[cli][parameters]") {
  const auto dir = fresh_dir("cps_parameters_docs");
  const cli_test::Result r = run_cps("parameters --format markdown", dir);
  REQUIRE(r.exit_code == 0);
  const std::string docs = between_markers(slurp(kSource / "docs/commands.md"), "cps parameters");
  INFO("docs/commands.md's table between the 'cps parameters' markers differs from `cps "
       "parameters`: run scripts/update-parameters.sh");
  CHECK(docs == r.out);
  // One row per parameter, and the header.
  std::size_t rows = 0;
  for (const char c : r.out) rows += c == '\n' ? 1 : 0;
  CHECK(rows == cps::world_parameters().size() + 2);
}

TEST_CASE("cps parameters --format tsv gives each option's type and range", "[cli][parameters]") {
  const auto dir = fresh_dir("cps_parameters_tsv");
  const cli_test::Result r = run_cps("parameters --format tsv", dir);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("--dt\treal\t1e-06\t1\t0\ts\n") != std::string::npos);
  CHECK(r.out.find("--iterations\tinteger\t1\t10000\t0\t\n") != std::string::npos);
  const cli_test::Result bad = run_cps("parameters --format yaml", dir);
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.find("yaml") != std::string::npos);
}
