// `cps report push` as a user runs it: every push method of the table side by side, its files,
// its physics (the paper's Fig. 7 point), and its refusals.
#include "cli_support.h"
#include "push_methods.h"
#include "report/push/cases.h"
#include "report/push/scorecard.h"
#include "report_csv.h"
#include "stress/stress.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace fs = std::filesystem;

namespace {

using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;

fs::path fresh_dir(const std::string& name) { return cli_test::fresh_dir("cps_cli_push_test_" + name); }

using Table = std::vector<std::map<std::string, std::string>>;

// True if `text` is a finite number, as a whole.
bool is_finite_number(const std::string& text) {
  if (text.empty()) return false;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(v);
}

// The row of `push` and `kase` at the scene's settings (variant "").
const std::map<std::string, std::string>& row_of(const Table& rows, const std::string& push,
                                                 const std::string& kase) {
  for (const auto& r : rows) {
    if (r.at("push") == push && r.at("case") == kase && r.at("variant").empty()) return r;
  }
  FAIL("no row for " << push << " " << kase);
  return rows.front();
}

double number_in(const std::map<std::string, std::string>& row, const std::string& column) {
  REQUIRE(is_finite_number(row.at(column)));
  return std::stod(row.at(column));
}

}  // namespace

TEST_CASE("cps report push --quick compares every push method of the table: files, measures, "
          "and split brings the intersecting stack to rest where baumgarte throws it",
          "[cli][report][push]") {
  const fs::path dir = fresh_dir("quick");
  const std::vector<std::string> methods = cli_test::push_method_names();
  REQUIRE(methods.size() >= 2);
  // A foreign push.md is refused (exit 2, named, kept), then replaced with --force.
  fs::create_directories(dir / "q");
  { std::ofstream(dir / "q" / "push.md") << "mine\n"; }
  const Result refused = run_cps("report push --quick --out q", dir);
  CHECK(refused.exit_code == 2);
  CHECK(refused.err.find("push.md") != std::string::npos);
  CHECK(slurp(dir / "q" / "push.md") == "mine\n");
  CHECK(!fs::exists(dir / "q" / "push.csv"));
  const Result r = run_cps("report push --quick --out q --force", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  for (const char* f : {"push.csv", "push.md", "push_overlap.png", "push_speed.png", "run.json",
                        "plots/push_overlap.gp", "plots/push_speed.dat"}) {
    INFO(f);
    CHECK(fs::is_regular_file(dir / "q" / f));
  }
  for (const char* png : {"push_overlap.png", "push_speed.png"}) {
    CHECK(slurp(dir / "q" / png).substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
  }
  // Each diagram also as a PDF of the same name, for a paper.
  for (const char* pdf : {"push_overlap.pdf", "push_speed.pdf"}) {
    CHECK(slurp(dir / "q" / pdf).substr(0, 5) == "%PDF-");
  }
  // The mass ratio scorecard: a row per method and setting (avbd's tuned pair, the exact solve),
  // case and ratio, each held (1, 0) or, only in the exact row, not run with the reason.
  const cli_test::CsvRows score = cli_test::read_report_csv(dir / "q" / "score.csv");
  CHECK(score.rows.size() == (2 * methods.size() + 3) * 3 * static_cast<std::size_t>(cps::cli::kScoreRatioPowers));
  for (const auto& row : score.rows) {
    INFO(row.at("push") << " " << row.at("variant") << " " << row.at("case") << " " << row.at("mass_ratio"));
    const std::string& held = row.at("held");
    if (held.empty()) {
      CHECK(row.at("variant") == "exact solve");
      CHECK(row.at("why").find("exact solve refused") != std::string::npos);
    } else {
      CHECK((held == "1") == row.at("why").empty());
    }
  }
  CHECK(slurp(dir / "q" / "push.md").find("## Mass ratio scorecard") != std::string::npos);

  // push.csv: one row per method per case, every column with its unit (or a name, not a
  // quantity), every measure a finite number or the documented "never" / "none".
  const cli_test::CsvRows csv = cli_test::read_report_csv(dir / "q" / "push.csv");
  const std::vector<std::string>& header = csv.columns;
  const Table& rows = csv.rows;
  const std::vector<std::string> cases = {"intersecting_stack", "sphere_in_box", "stack",
                                          "mass_ratio", "pendulum_grid", "pendulum_wave",
                                          "heavy_on_light", "heavy_rope", "stack_20_long",
                                          "pyramid_20_rows_long"};
  // A row per method and case, and the tuned avbd rows of the two heavy cases.
  CHECK(rows.size() == methods.size() * cases.size() + 2);
  std::set<std::tuple<std::string, std::string, std::string>> seen;
  for (const auto& row : rows) seen.emplace(row.at("push"), row.at("case"), row.at("variant"));
  CHECK(seen.size() == rows.size());
  for (const std::string& m : methods) {
    for (const std::string& c : cases) CHECK(seen.count({m, c, ""}) == 1);
  }
  const std::string tuned = "avbd_k_start=1e+06";
  CHECK(seen.count({"avbd", "heavy_on_light", tuned}) == 1);
  CHECK(seen.count({"avbd", "heavy_rope", tuned}) == 1);
  // The tuned avbd rows hold the heavy cases for their 10 s (the in-process test below says
  // why), and so hold the scenes' mass ratios: 32768 and 1800.
  for (const auto& row : rows) {
    if (row.at("variant") != tuned) continue;
    INFO(row.at("case"));
    CHECK(row.at("survival_s") == "never");
    CHECK(row.at("largest_mass_ratio_held") == (row.at("case") == "heavy_on_light" ? "32768" : "1800"));
  }
  const std::set<std::string> unitless = {"push", "case", "variant", "iterations",
                                          "mass_ratios_held", "largest_mass_ratio_held"};
  for (const std::string& c : header) {
    INFO(c);
    const bool has_unit = c.size() > 2 && (c.ends_with("_s") || c.ends_with("_m") ||
                                           c.ends_with("_mps") || c.ends_with("_J") ||
                                           c.ends_with("_rel") || c.ends_with("_deg") ||
                                           c == "us_per_step");
    CHECK((has_unit || unitless.count(c)));
  }
  for (const auto& row : rows) {
    for (const auto& [column, cell] : row) {
      if (cell.empty() || column == "push" || column == "case" || column == "variant") continue;
      INFO(row.at("push") << " " << row.at("case") << " " << column << " = " << cell);
      if (column == "final_heights_m" || column == "rest_heights_m" || column == "mass_ratios_held") {
        std::stringstream s(cell);
        for (std::string v; s >> v;) CHECK((is_finite_number(v) || v == "none"));
        continue;
      }
      CHECK((is_finite_number(cell) || cell == "never" || cell == "none"));
    }
  }
  for (const std::string& m : methods) {
    INFO(m);
    // The resting column, from the cubes' half extent 1.2 m: centres at 1.2 (2 i + 1) m.
    std::stringstream rest(row_of(rows, m, "intersecting_stack").at("rest_heights_m"));
    int i = 0;
    for (double y; rest >> y; ++i) CHECK(y == Approx(1.2 * (2 * i + 1)).margin(1e-9));
    CHECK(i == 5);
    CHECK(row_of(rows, m, "sphere_in_box").at("rest_heights_m") == "1 2.4");
    CHECK(number_in(row_of(rows, m, "stack"), "seconds_s") == Approx(60.0));
    CHECK(number_in(row_of(rows, m, "stack"), "us_per_step") > 0.0);
    CHECK(number_in(row_of(rows, m, "intersecting_stack"), "us_per_step") > 0.0);
    // The hard cases: the heavy ones over their 10 s, the long ones over 600 of their 10,000
    // steps of 1/60 s in --quick; each at the scene's 25 iterations.
    for (const char* kase : {"heavy_on_light", "heavy_rope"}) {
      CHECK(number_in(row_of(rows, m, kase), "seconds_s") == Approx(10.0));
    }
    for (const char* kase : {"stack_20_long", "pyramid_20_rows_long"}) {
      CHECK(number_in(row_of(rows, m, kase), "seconds_s") == Approx(600.0 / 60.0));
    }
    for (const char* kase : {"heavy_on_light", "heavy_rope", "stack_20_long", "pyramid_20_rows_long"}) {
      INFO(kase);
      CHECK(row_of(rows, m, kase).at("iterations") == "25");
      CHECK(number_in(row_of(rows, m, kase), "us_per_step") > 0.0);
    }
  }

  // Fig. 7 of the paper: with the push kept in the velocity (baumgarte) the overlapping cubes
  // fly apart, with the single frame push factor (split) they are moved apart and come to rest.
  // A cube pushed out of 0.4 m of overlap at beta d / dt = 0.2 x 0.4 x 60 = 4.8 m/s per contact
  // keeps that speed under baumgarte; under split it keeps none of it.
  const auto& baumgarte = row_of(rows, "baumgarte", "intersecting_stack");
  const auto& split = row_of(rows, "split", "intersecting_stack");
  CHECK(number_in(split, "peak_speed_mps") < number_in(baumgarte, "peak_speed_mps"));
  CHECK(number_in(baumgarte, "peak_speed_mps") > 4.8);
  CHECK(number_in(split, "peak_speed_mps") < 1.0);
  // Split ends near the resting column (within 1 cm); baumgarte has thrown it metres off.
  CHECK(number_in(split, "final_height_error_m") < 0.01);
  CHECK(number_in(baumgarte, "final_height_error_m") > 1.0);
  // The energy injected above rest: 5 cubes of 1.2 kg, 10 m/s^2: a metre of height is 12 J per
  // cube. Split stays within 1 J, baumgarte throws the cubes tens of metres up.
  CHECK(std::abs(number_in(split, "energy_injected_J")) < 1.0);
  CHECK(number_in(baumgarte, "energy_injected_J") > 100.0);

  // push.md: one table row per method, in the table's order, each with as many cells as the
  // header, every cell a number or a documented word.
  const std::string md = slurp(dir / "q" / "push.md");
  std::stringstream lines(md);
  std::vector<std::string> table;
  bool in_table = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("| method |", 0) == 0) {
      in_table = true;
      table.push_back(line);
    } else if (in_table && line.rfind("|", 0) == 0) {
      table.push_back(line);
    } else if (in_table) {
      break;
    }
  }
  REQUIRE(table.size() == methods.size() + 2);  // header, separator, a row per method
  const auto cells = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream s(line.substr(1));
    for (std::string c; std::getline(s, c, '|');) out.push_back(c.substr(1, c.size() - 2));
    return out;
  };
  const std::size_t columns = cells(table[0]).size();
  for (std::size_t k = 0; k < methods.size(); ++k) {
    const std::vector<std::string> row = cells(table[k + 2]);
    INFO(table[k + 2]);
    REQUIRE(row.size() == columns);
    CHECK(row[0].rfind(methods[k], 0) == 0);
    for (std::size_t c = 1; c < row.size(); ++c) {
      CHECK((is_finite_number(row[c]) || row[c] == "never" || row[c] == "-" || row[c] == "none"));
    }
  }
  CHECK(md.find("--quick") != std::string::npos);  // the legend says the stack ran 60 s
  // A section per hard case, the tuned row labelled as such.
  for (const char* kase : {"heavy_on_light", "heavy_rope", "stack_20_long", "pyramid_20_rows_long"}) {
    CHECK(md.find(std::string("### ") + kase + "\n") != std::string::npos);
  }
  CHECK(md.find("tuned variant, not the scene's settings") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("cps report push refuses sweep options and bad names, naming them, writing nothing",
          "[cli][report][push]") {
  const fs::path dir = fresh_dir("refused");
  fs::create_directories(dir / "runs");
  struct Case {
    std::string args;
    std::vector<std::string> says;
  };
  const std::vector<Case> cases = {
      {"report push --run x --out out", {"push", "--run"}},
      {"report push --run intersecting_stack.pgs.baumgarte.fixed.it1.ss1 --out out", {"push", "--run"}},
      {"report push --merge runs --out out", {"push", "--merge"}},
      {"report push --list-runs --out out", {"push", "--list-runs"}},
      {"report pushh --out out", {"'pushh'", "'push'"}},
      {"report PUSH --out out", {"'PUSH'", "'push'"}},
      {"report push --seed 3 --out out", {"push", "--seed"}},
      {"report push --out ''", {"--out"}},
  };
  for (const Case& c : cases) {
    INFO("cps " << c.args);
    const Result r = run_cps(c.args, dir);
    CHECK(r.exit_code == 2);
    for (const std::string& s : c.says) {
      INFO(s << " in: " << r.err);
      CHECK(r.err.find(s) != std::string::npos);
    }
    CHECK(!fs::exists(dir / "out"));
  }
  // cps list and report's help name the comparison.
  CHECK(run_cps("list", dir).out.find("cps report push") != std::string::npos);
  CHECK(run_cps("report --help", dir).out.find("'push'") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("report push's hard cases: tuned avbd holds heavy_on_light and heavy_rope where PGS at "
          "25 iterations lets them go",
          "[cli][report][push]") {
  using namespace cps::cli;
  const cps::scenes::Scene* heavy = cps::scenes::find_scene("heavy_on_light");
  const cps::scenes::Scene* rope = cps::scenes::find_scene("heavy_rope");
  REQUIRE(heavy);
  REQUIRE(rope);
  const std::optional<Method> avbd = push_method_named("avbd");
  REQUIRE(avbd);
  // 2 s: 120 steps of 1/60 s. The small configuration: the report runs 10 s.
  const double seconds = 2.0;
  // The leave distance: half the bottom cube's 0.1 m edge; half a link's size on the rope.
  const double heavy_leave = 0.5 * cps::scenes::kHeavyOnLightSmallestEdgeM;

  // AVBD with its penalties from 1e6 N/m holds the 32768:1 stack: no body leaves its place by
  // the leave distance, so no contact can be deeper than it either (the bottom cube, sunk that
  // far into the ground, would have left its place), and the mass ratio it holds is the scene's.
  const HardResult tuned = run_hard_case(*heavy, *avbd, seconds, kTunedAvbdKStart);
  CHECK(tuned.iterations == 25);
  CHECK_FALSE(tuned.diverged_at);
  CHECK(tuned.held_throughout());
  CHECK(metric(tuned.metrics, "leave_distance_m") == Approx(heavy_leave));
  CHECK(metric(tuned.metrics, "max_penetration_m") < heavy_leave);
  CHECK(metric(tuned.metrics, "mass_ratio") == Approx(32768.0));
  CHECK(tuned.variant == "avbd_k_start=1e+06");

  // Every PGS push method at the scene's 25 iterations loses it within the 2 s. Gauss-Seidel on
  // two resting cubes, the upper M = 8 m, has the iteration matrix's spectral radius
  // (1/m^2) / ((1/m) (1/m + 1/M)) = M / (M + m) = 8/9 (A = J M^-1 J^T of the two contacts), so
  // 25 cold sweeps leave (8/9)^25 = 5 % of the pair's error, and the six-cube chain converges
  // no faster: the light cubes do not get the impulse that carries the 37448 kg above them.
  for (const Method& m : push_methods()) {
    if (m.name == "avbd") continue;
    INFO(m.name);
    const HardResult r = run_hard_case(*heavy, m, seconds);
    CHECK_FALSE(r.held_throughout());
    if (!r.diverged_at) CHECK(metric(r.metrics, "survival_s") < seconds);
    CHECK(std::isfinite(metric(r.metrics, "energy_injected_J")));
    CHECK(metric(r.metrics, "energy_injected_J") >= 0.0);
  }

  // The rope: avbd from 1e6 N/m holds the 180 kg block on its 0.1 kg links. Each rod carries at
  // most the block and the links, (180 + 20 x 0.1) kg x 10 m/s^2 = 1820 N; a penalty of at
  // least k_start stretches under it by at most 1820 / 1e6 m at rest and twice that when the
  // load comes on at once (a spring under a suddenly applied load), 3.64 mm; the augmented
  // Lagrangian's lambda only takes stretch away.
  const HardResult rope_tuned = run_hard_case(*rope, *avbd, seconds, kTunedAvbdKStart);
  CHECK(rope_tuned.has_rods);
  CHECK_FALSE(rope_tuned.diverged_at);
  CHECK(rope_tuned.held_throughout());
  const double load_N = (cps::scenes::kHeavyRopeBlockRatio + cps::scenes::kHeavyRopeLinks) *
                        cps::scenes::kHeavyRopeLinkMassKg * 10.0;
  CHECK(metric(rope_tuned.metrics, "max_rod_stretch_m") < 2.0 * load_N / kTunedAvbdKStart);
  CHECK(metric(rope_tuned.metrics, "mass_ratio") == Approx(cps::scenes::kHeavyRopeBlockRatio));
  CHECK(std::isfinite(metric(rope_tuned.metrics, "energy_injected_J")));
  // Baumgarte (the paper's push) at 25 iterations lets the block down.
  const std::optional<Method> baumgarte = push_method_named("baumgarte");
  REQUIRE(baumgarte);
  const HardResult rope_pgs = run_hard_case(*rope, *baumgarte, seconds);
  CHECK_FALSE(rope_pgs.held_throughout());
  CHECK(std::isfinite(metric(rope_pgs.metrics, "energy_injected_J")));
}
