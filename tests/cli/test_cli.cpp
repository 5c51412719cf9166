// The cps command as a user runs it: exit codes, messages, and that bad input writes nothing.
#include "cli_support.h"
#include "push_methods.h"
#include "report_csv.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;

Result cps(const std::string& args, const fs::path& dir) { return run_cps(args, dir); }

fs::path fresh_dir(const std::string& name) { return cli_test::fresh_dir("cps_cli_test_" + name); }

// A command line that must be refused, and what its message must name.
struct Case {
  std::string args;
  std::string says;
};

// Each case exits with 2, its message names what it says, and nothing is written to dir/out.
void expect_refused(const std::vector<Case>& cases, const fs::path& dir) {
  for (const Case& c : cases) {
    INFO("cps " << c.args);
    const Result r = cps(c.args, dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
    CHECK(!fs::exists(dir / "out"));
  }
}

// The rows of a report CSV, each as column name -> cell ("" where empty).
std::vector<std::map<std::string, std::string>> read_table(const fs::path& file) {
  return cli_test::read_report_csv(file).rows;
}

double value(const std::map<std::string, std::string>& row, const std::string& column) {
  const auto it = row.find(column);
  return it == row.end() || it->second.empty() ? std::nan("") : std::stod(it->second);
}

using cli_test::paper_push_methods;
using cli_test::push_methods;

// The quick sweep of one scene, as `cps report --quick` defines it: cold runs at iterations 1,
// 4, 16, 25, 64 (1 substep) and 4 substeps (25 iterations) for each push method of the table,
// with solver pgs, and jacobi too for the paper's push methods, fixed friction; and PGS
// warm-started at factors 0.8 and 1 at iterations 1, 4, 16, 25 (1 substep), Baumgarte push,
// fixed friction. With baumgarte and split: (5 + 1) x 2 x 2 + 8 = 32.
const int kQuickCold = (5 + 1) * (2 * paper_push_methods() + (push_methods() - paper_push_methods()));
const int kQuickWarm = 2 * 4;
const int kQuickRuns = kQuickCold + kQuickWarm;

// The rows of the mass ratio table, a study each in every sweep's plan: ratios 10, 100, 1000 x
// every push method x the solvers it reads.
int mass_ratio_studies() {
  int variants = 0;
  for (const cli_test::Reads& r : cli_test::push_method_reads()) variants += r.solver ? 2 : 1;
  return 3 * variants;
}

// The warm start factor of a report CSV row; 0 where the column is empty.
double warm_of(const std::map<std::string, std::string>& row) {
  const double w = value(row, "warm_start");
  return std::isnan(w) ? 0.0 : w;
}

// True if the number at the start of `text` ("0.815 (0.809 to 0.820)") is `v` rounded to the
// significant digits the text shows: within half a unit of its last digit.
bool as_printed(const std::string& text, double v) {
  std::size_t end = 0;
  const double shown = std::stod(text, &end);
  const std::string mantissa = text.substr(0, std::min(end, text.find_first_of("eE")));
  int digits = 0;
  bool leading = true;
  for (const char c : mantissa) {
    if (c < '0' || c > '9') continue;
    if (c != '0') leading = false;
    if (!leading) ++digits;
  }
  if (digits == 0) return v == 0.0;
  const double unit = std::pow(10.0, std::floor(std::log10(std::abs(shown))) - digits + 1);
  INFO(text << " against " << v);
  return std::abs(shown - v) <= 0.5 * unit * (1.0 + 1e-9);
}

// Checks report.md's table "Warm starting: what PGS needs to reach the paper's error" of
// `scene` against the scene's CSV rows: for each warm start factor of the table, the fewest
// iterations is the smallest count among the runs at PGS, Baumgarte, fixed friction, 1 substep
// and that factor whose `measure` is at most the paper's run's (25 it, cold), not diverged;
// every smaller count of that line does not reach it; the saved iterations are 25 minus the
// count, the time ratio that run's time over the paper's. Returns the fewest count per factor
// (-1 for "none in this sweep").
std::map<double, int> check_warm_table(const std::string& md, const std::string& scene,
                                       const std::vector<std::map<std::string, std::string>>& rows,
                                       const std::string& measure) {
  const auto line_of = [](const auto& r) {
    return r.at("solver") == "pgs" && r.at("push") == "baumgarte" &&
           r.at("friction_model") == "fixed" && r.at("substeps") == "1";
  };
  const std::map<std::string, std::string>* paper = nullptr;
  for (const auto& r : rows) {
    if (line_of(r) && r.at("iterations") == "25" && warm_of(r) == 0.0) paper = &r;
  }
  REQUIRE(paper != nullptr);
  REQUIRE(paper->at("diverged") == "0");
  // A run's value, ranked: a run that never recovered (metric.recovered 0) after every other.
  const auto ranked = [&](const std::map<std::string, std::string>& r) -> double {
    const auto rec = r.find("metric.recovered");
    if (measure == "metric.recovery_time_s" && rec != r.end() && rec->second == "0") return INFINITY;
    return value(r, measure);
  };
  const double e0 = ranked(*paper);
  // Reaching a paper's run that never recovered is recovering.
  const auto reaches = [&](double v) { return std::isinf(e0) ? std::isfinite(v) : v <= e0; };
  const double t0 = value(*paper, "cpu_s_per_sim_s");
  const std::size_t section = md.find("## " + scene + "\n");
  REQUIRE(section != std::string::npos);
  const std::size_t table = md.find("### Warm starting: what PGS needs to reach the paper's error", section);
  REQUIRE(table != std::string::npos);
  std::stringstream lines(md.substr(md.find("|---", table)));
  std::string line;
  std::getline(lines, line);  // the separator
  std::map<double, int> fewest;
  while (std::getline(lines, line) && line.rfind("| ", 0) == 0) {
    std::vector<std::string> cells;
    std::stringstream cs(line.substr(2));
    for (std::string c; std::getline(cs, c, '|');) {
      c.erase(0, c.find_first_not_of(' '));
      c.erase(c.find_last_not_of(' ') + 1);
      cells.push_back(c);
    }
    REQUIRE(cells.size() >= 6);
    const double w = std::stod(cells[0]);
    INFO(scene << " warm start " << w);
    int expected = -1;
    for (const auto& r : rows) {
      if (!line_of(r) || warm_of(r) != w || r.at("diverged") == "1") continue;
      const int n = std::stoi(r.at("iterations"));
      if (reaches(ranked(r)) && (expected < 0 || n < expected)) expected = n;
    }
    if (cells[1] == "none in this sweep") {
      CHECK(expected == -1);
      fewest[w] = -1;
      continue;
    }
    const int n = std::stoi(cells[1]);
    CHECK(n == expected);
    fewest[w] = n;
    for (const auto& r : rows) {
      if (!line_of(r) || warm_of(r) != w) continue;
      const int it = std::stoi(r.at("iterations"));
      if (it == n) {
        CHECK(r.at("diverged") == "0");
        CHECK(reaches(ranked(r)));
        CHECK(std::stod(cells[2]) == Approx(value(r, measure)).epsilon(1e-5));
        // The ratio as printed: to the digits it was printed with (its quartiles' range after it).
        CHECK(as_printed(cells[4], value(r, "cpu_s_per_sim_s") / t0));
      }
      if (it < n) CHECK((r.at("diverged") == "1" || !reaches(ranked(r))));
    }
    CHECK(std::stoi(cells[5]) == 25 - n);
  }
  // The cold start and the two warm factors of the sweep.
  CHECK(fewest.count(0.0) == 1);
  CHECK(fewest.count(0.8) == 1);
  CHECK(fewest.count(1.0) == 1);
  // The paper's run itself reaches the paper's error (where it has one: recovering is more).
  if (std::isfinite(e0)) {
    CHECK(fewest[0.0] >= 1);
    CHECK(fewest[0.0] <= 25);
  }
  return fewest;
}

// Writes a scene file of one 1 kg box resting on a plane for 0.2 s at `path`: a report's quick
// sweep over it takes milliseconds a run.
void write_drop_scene(const fs::path& path) {
  std::ofstream(path) << R"({"seconds": 0.2, "bodies": [{"shape": "plane", "normal": [0, 1, 0], "offset_m": 0},)"
                         R"( {"shape": "box", "half_extents_m": [0.5, 0.5, 0.5], "mass_kg": 1, "position_m": [0, 0.6, 0]}]})";
}

}  // namespace

TEST_CASE("bad arguments exit with 2, name the problem and write nothing", "[cli]") {
  const fs::path dir = fresh_dir("bad");
  std::vector<Case> cases = {
      {"render nosuchscene", "unknown scene 'nosuchscene'"},
      {"simulate nosuchscene", "'cps list' shows"},  // the nearest name, and where the list is
      {"render stack --size 12x", "--size"},
      {"render stack --size 8x8", "[16, 8192]"},
      {"render stack --fps 0", "--fps"},
      {"render stack --seconds -1", "--seconds"},
      {"render stack --seconds nan", "--seconds"},
      {"render stack --dt abc", "--dt"},
      {"render stack --iterations 0", "--iterations"},
      {"simulate stack --beta 1.5", "--beta"},
      {"simulate stack --friction -0.1", "--friction"},
      {"simulate stack --push sideways", "baumgarte, split"},
      {"render stack --compare push --push split", "--compare push"},
      {"frobnicate", "unknown command 'frobnicate'"},
      {"--nosuch", "--nosuch"},
      {"-z simulate stack", "-z"},
  };
  for (Case& c : cases) {
    if (c.args.rfind("render", 0) == 0) c.args += " --out out";
  }
  expect_refused(cases, dir);
  fs::remove_all(dir);
}

TEST_CASE("work that would not end and malformed numbers are refused before any work",
          "[cli][limits]") {
  const fs::path dir = fresh_dir("limits");
  const std::vector<Case> cases = {
      // Runs that would take forever or overflow a count.
      {"simulate stack --seconds 1e12", "--seconds"},
      {"simulate stack --seconds 1e5 --dt 1e-6", "steps"},
      {"simulate stack --dt 1e-300", "--dt"},
      {"simulate stack --dt 5e-324", "--dt"},
      {"simulate stack --dt 1e308", "--dt"},
      {"simulate stack --iterations 1000000", "--iterations"},
      {"report --run stack.pgs.baumgarte.fixed.it100000.ss100000 --out out", "it100000"},
      {"report --run pendulum_wave.pgs.baumgarte.fixed.it25.ss1001 --out out", "ss1001"},
      // Numbers read one way: decimal, whole, nothing after.
      {"simulate stack --iterations 0x10", "--iterations"},
      {"simulate stack --friction 0x10", "--friction"},
      {"simulate stack --contact-margin 0x10", "--contact-margin"},
      {"simulate stack --dt 0x10", "--dt"},
      {"simulate stack --seconds 1s", "--seconds"},
      {"simulate stack --dt 1/0", "--dt"},
      {"report --run stack.pgs.baumgarte.fixed.it4294967297.ss1 --out out", "it4294967297"},
      {"report --run stack.pgs.baumgarte.fixed.it1x.ss1 --out out", "it1x"},
      // Warm start factors: decimal, in [0, 1], nothing after.
      {"report --run stack.pgs.baumgarte.fixed.it1.ss1.ws2 --out out", "'ws2' is not a warm start factor in [0, 1]"},
      {"report --run stack.pgs.baumgarte.fixed.it1.ss1.ws-0.5 --out out", "'ws-0.5' is not a warm start factor in [0, 1]"},
      {"report --run stack.pgs.baumgarte.fixed.it1.ss1.wsnan --out out", "'wsnan'"},
      {"report --run stack.pgs.baumgarte.fixed.it1.ss1.ws0.5x --out out", "'ws0.5x'"},
      {"report --run stack.pgs.baumgarte.fixed.it1.ss1.ws --out out", "'ws' is not a warm start factor"},
      // Empty names mean nothing: refused.
      {"report --run '' --out out", "--run"},
      {"report stack --out ''", "--out"},
      {"report --merge '' --out out", "--merge"},
      {"simulate stack --trace ''", "--trace"},
      {"simulate stack --expect-hash ''", "--expect-hash"},
#ifdef CPS_HAVE_RENDERER
      {"render stack --seconds 1e12 --out out", "--seconds"},
      {"render stack --seconds 1e8 --out out", "--seconds"},
      {"render stack --fps 1e308 --out out", "--fps"},
      {"render stack --fps 1e9 --seconds 0.2 --out out", "--fps"},
      {"render stack --fps 1000 --seconds 1000 --out out", "frames"},
      {"render stack --out ''", "--out"},
      {"figure stack --times 0,1 --out ''", "--out"},
      {"figure stack --times 0,1e12 --out out/f.png", "--times"},
      {"figure stack --times 0,1e5 --dt 1e-6 --out out/f.png", "steps"},
#endif
  };
  expect_refused(cases, dir);
  // A time step may be given as a fraction, and means exactly that value.
  const Result fraction = cps("simulate stack --seconds 0.1 --dt 1/60 --json", dir);
  REQUIRE(fraction.exit_code == 0);
  CHECK(nlohmann::json::parse(fraction.out)["parameters"]["dt_s"].get<double>() == 1.0 / 60.0);
  fs::remove_all(dir);
}

TEST_CASE("cps --version names the build, list and unknown scenes name the scaled families",
          "[cli]") {
  const fs::path dir = fresh_dir("version");
  const Result version = cps("--version", dir);
  CHECK(version.exit_code == 0);
  CHECK(version.out.rfind("cps ", 0) == 0);
  const Result list = cps("list", dir);
  CHECK(list.exit_code == 0);
  for (const char* family : {"stack_N", "pyramid_N", "funnel_N", "pendulum_wave_N", "pendulum_grid_N"}) {
    CHECK(list.out.find(family) != std::string::npos);
  }
  const Result unknown = cps("simulate pyramid", dir);
  CHECK(unknown.exit_code == 2);
  CHECK(unknown.err.find("pyramid_N (about N boxes, 1..20000)") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("cps report's quick funnel sweep: trajectory errors where the balls are in the funnel, "
          "diverged runs flagged and timed, a blow-up far off", "[cli][report]") {
  const fs::path dir = fresh_dir("funnel");
  const Result r = cps("report funnel --quick --out q", dir);
  REQUIRE(r.exit_code == 0);
  const auto rows = read_table(dir / "q/funnel.csv");
  REQUIRE(rows.size() == static_cast<std::size_t>(kQuickRuns));
  const auto find = [&](const std::string& solver, const std::string& push, int it, int ss) {
    for (const auto& row : rows) {
      if (row.at("solver") == solver && row.at("push") == push && warm_of(row) == 0.0 &&
          row.at("iterations") == std::to_string(it) && row.at("substeps") == std::to_string(ss)) {
        return row;
      }
    }
    FAIL("no run " << solver << " " << push << " it" << it << " ss" << ss);
    return rows.front();
  };
  // The balls are 1 m across. Jacobi at 60 Hz and 16 iterations pushes them metres into each
  // other and the walls (212 m by 10 s, once reported as not diverged); PGS at the paper's
  // settings keeps the penetration under 0.2 m.
  CHECK(find("jacobi", "baumgarte", 16, 1).at("diverged") == "1");
  CHECK(find("pgs", "baumgarte", 25, 1).at("diverged") == "0");
  // The balls reach the walls at about 1 s. At 1 s every run at 60 Hz was 0.0707 m from the
  // reference, whatever its iterations: the free fall's time-step error, before any contact.
  // At the funnel's trajectory time the pile has formed and come to rest; a solve of 1 sweep
  // leaves it sagging and spread far more than 64 sweeps do (by over a factor 2).
  for (const std::string push : {"baumgarte", "split"}) {
    INFO(push);
    std::vector<double> errors;
    for (const int it : {1, 4, 16, 25, 64}) errors.push_back(value(find("pgs", push, it, 1), "trajectory_error_m"));
    for (const double e : errors) REQUIRE(e >= 0.0);
    CHECK(errors.front() > 2.0 * errors.back());
    CHECK(value(find("pgs", push, 25, 1), "trajectory_time_s") > 3.0);  // after the pile settles
  }
  int diverged = 0;
  for (const auto& row : rows) {
    if (row.at("diverged") != "1") continue;
    ++diverged;
    INFO(row.at("solver") << " " << row.at("push") << " it" << row.at("iterations"));
    // Timed until it diverged, so that the diagrams can place it.
    CHECK(value(row, "cpu_s_per_sim_s") > 0.0);
    CHECK(value(row, "diverged_at_s") > 0.0);
    CHECK(value(row, "diverged_at_s") <= value(row, "horizon_s"));
  }
  CHECK(diverged >= 1);
  // Every diverged run says why (a bound passed or a state blown up), and report.md's omissions
  // table of the funnel lists exactly the diverged runs (PGS keeps a value of the trajectory
  // error, the funnel's measure, in every run that finished).
  const std::string md = slurp(dir / "q/report.md");
  const std::size_t section = md.find("## funnel\n");
  const std::size_t omitted = md.find("### Omissions", section);
  REQUIRE(omitted != std::string::npos);
  const std::string table = md.substr(omitted, md.find("\n## ", omitted) - omitted);
  for (const auto& row : rows) {
    const std::string id = "`funnel." + row.at("solver") + "." + row.at("push") + "." +
                           row.at("friction_model") + ".it" + row.at("iterations") + ".ss" +
                           row.at("substeps") + (warm_of(row) != 0.0 ? ".ws" + row.at("warm_start") : "") + "`";
    INFO(id);
    const bool listed = table.find(id + " |") != std::string::npos;
    if (row.at("diverged") == "1") {
      CHECK(listed);
      const std::string why = row.at("diverged_why");
      CHECK((why == "not finite" || why.rfind("penetration ", 0) == 0 || why.rfind("rod error ", 0) == 0 ||
             why.rfind("a body ", 0) == 0));
      CHECK(table.find(why) != std::string::npos);
    } else {
      CHECK(listed == std::isnan(value(row, "trajectory_error_m")));
      CHECK(row.at("diverged_why").empty());
    }
    // A trajectory error under its reference's own error (the Richardson estimate), or whose
    // reference has none (its distances do not shrink with dt), is flagged, and only then.
    if (!std::isnan(value(row, "trajectory_error_m"))) {
      const double own = value(row, "reference_error_m");
      CHECK(row.at("under_reference_error") ==
            (std::isnan(own) || value(row, "trajectory_error_m") < own ? "1" : "0"));
      // The estimate is d2 / (2^p - 1) from the order p and the distance d2 beside it.
      if (!std::isnan(own) && own > 0.0) {
        CHECK(own == Approx(value(row, "reference_check_m") /
                            (std::exp2(value(row, "reference_order")) - 1.0)).epsilon(1e-4));
      }
    }
  }
  // The paper's push converges in dt on the funnel at its trajectory time (the references at 2,
  // 4 and 8 substeps shrink their distances), and its run at 4 substeps is resolved against it;
  // the runs flagged (soft and xpbd, whose references do not converge there) are drawn with
  // their own mark and key entry.
  CHECK(value(find("pgs", "baumgarte", 25, 4), "reference_order") > 0.0);
  CHECK(find("pgs", "baumgarte", 25, 4).at("under_reference_error") == "0");
  CHECK(std::any_of(rows.begin(), rows.end(),
                    [](const auto& row) { return row.at("under_reference_error") == "1"; }));
  CHECK(slurp(dir / "q/plots/funnel_trajectory_error_m.gp").find("below the reference''s own error, or it unknown: not resolved") !=
        std::string::npos);
  // The headline states the dt of the paper's run: the paper's 1/60 s.
  CHECK(md.find("| funnel | RMS distance from the reference run at the trajectory time (m) | 1/60 s | ") !=
        std::string::npos);
  // Warm-started PGS: the paper's error (trajectory error at 25 it, cold) reached with fewer
  // iterations or not at all, as report.md's table says and the CSV confirms.
  check_warm_table(slurp(dir / "q/report.md"), "funnel", rows, "trajectory_error_m");
  // The quick sweep checks its two references at its own reference substeps, 8 a frame: at most
  // one exact solve a step, so at most 3.5 s x 60 x 8 = 1680 to the trajectory time (16 substeps
  // would take 2350 solves there).
  CHECK(md.find("Two independent references at the same small dt (8 substeps per 1/60 s frame") !=
        std::string::npos);
  const auto agreement = read_table(dir / "q/funnel_references.csv");
  REQUIRE(!agreement.empty());
  CHECK(value(agreement.front(), "checked_until_s") == Approx(3.5));
  CHECK(value(agreement.front(), "exact_solves") <= 3.5 * 60 * 8);
  // Jacobi with the coupled friction model blows the balls apart within 1.3 s, before the
  // trajectory time: it steps on to it, and the blow-up has carried the balls further from the
  // reference pile than a ball's radius.
  const std::string id = "funnel.jacobi.baumgarte.coupled.it32.ss1";
  REQUIRE(cps("report funnel --run " + id + " --out runs", dir).exit_code == 0);
  const auto blown = read_table(dir / "runs" / (id + ".csv")).at(0);
  CHECK(blown.at("diverged") == "1");
  CHECK(value(blown, "diverged_at_s") < value(blown, "trajectory_time_s"));
  CHECK(value(blown, "trajectory_error_m") > 0.5);
  fs::remove_all(dir);
}

TEST_CASE("cps list names every scene of the paper", "[cli]") {
  const fs::path dir = fresh_dir("list");
  const Result r = cps("list", dir);
  CHECK(r.exit_code == 0);
  for (const char* scene :
       {"stack", "intersecting_stack", "funnel", "pendulum_grid", "pendulum_wave"}) {
    CHECK(r.out.find(scene) != std::string::npos);
  }
  fs::remove_all(dir);
}

TEST_CASE("cps simulate --json reports parameters, metrics and the final bodies", "[cli]") {
  const fs::path dir = fresh_dir("json");
  const Result r = cps("simulate stack --seconds 1 --dt 0.01 --json", dir);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  CHECK(j["scene"] == "stack");
  CHECK(j["parameters"]["dt_s"].get<double>() == Approx(0.01));
  CHECK(j["parameters"]["iterations"] == 25);
  CHECK(j["steps"] == 100);
  CHECK(j["simulated_s"].get<double>() == Approx(1.0));
  for (const char* key : {"wall_s", "us_per_step"}) CHECK(j[key].get<double>() > 0.0);
  for (const char* key : {"slide_off_time_s", "max_drift_m", "creep_m", "max_tilt_deg", "max_penetration_m"}) {
    CHECK(j["metrics"].contains(key));
  }
  for (const char* key : {"pairs_tested", "contacts", "rows", "solves"}) {
    CHECK(j["counters"].contains(key));
  }
  REQUIRE(j["bodies"].size() == 5);
  // After 1 s the lowest cube has fallen 0.8 m onto the ground: centre at about 1.2 m.
  CHECK(j["bodies"][0]["position"][1].get<double>() == Approx(1.2).margin(0.05));
  CHECK(j["bodies"][0]["orientation"].size() == 4);
  fs::remove_all(dir);
}

TEST_CASE("cps bench --scene --json times each scene over a window where it is in contact",
          "[cli][bench]") {
  const fs::path dir = fresh_dir("bench_json");
  const Result r = cps("bench --quick --json --scene intersecting_stack --scene funnel", dir);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  REQUIRE(j["physics"].size() == 2);
  CHECK_FALSE(j.contains("growth"));
  CHECK_FALSE(j.contains("rendering"));
  for (const nlohmann::json& row : j["physics"]) {
    INFO(row.dump());
    for (const char* key : {"explicit_us_per_step", "matrix_free_us_per_step"}) {
      CHECK(std::isfinite(row[key].get<double>()));
      CHECK(row[key].get<double>() > 0.0);
    }
    // Timed while the bodies touch: contact points in every scene's window.
    CHECK(row["contacts_per_step"].get<double>() > 0.0);
    CHECK(row["window_end_s"].get<double>() > row["window_start_s"].get<double>());
    CHECK(row["repeats"].get<int>() >= 5);
  }
  // The intersecting stack's cubes part about 0.12 s in and fly until about 3.4 s: its window
  // must close before they part.
  CHECK(j["physics"][0]["scene"] == "intersecting_stack");
  CHECK(j["physics"][0]["window_end_s"].get<double>() <= 0.12);
  CHECK(cps("bench --scene no_such_scene", dir).exit_code == 2);
  CHECK(cps("bench --scene stack --rendering", dir).exit_code == 2);
  fs::remove_all(dir);
}

TEST_CASE("cps bench --scene steps the world parameters it is given", "[cli][bench]") {
  const fs::path dir = fresh_dir("bench_params");
  // Without friction a contact point has one row, with it three (Sec. 5.4): the parameters reach
  // the timed world. On two threads the time is the wall clock's.
  const Result plain = cps("bench --quick --json --scene intersecting_stack", dir);
  const Result frictionless = cps(
      "bench --quick --json --scene intersecting_stack --friction 0 --solver coloured-pgs "
      "--threads 2", dir);
  REQUIRE(plain.exit_code == 0);
  REQUIRE(frictionless.exit_code == 0);
  const nlohmann::json p = nlohmann::json::parse(plain.out)["physics"][0];
  const nlohmann::json f = nlohmann::json::parse(frictionless.out)["physics"][0];
  CHECK(p["rows_per_step"].get<double>() == Approx(3.0 * p["contacts_per_step"].get<double>()));
  CHECK(f["rows_per_step"].get<double>() == Approx(f["contacts_per_step"].get<double>()));
  CHECK(p["threads"] == 1);
  CHECK(p["clock"] == "thread_cpu");
  CHECK(f["threads"] == 2);
  CHECK(f["clock"] == "wall");
  // The full tables run each scene at its own settings; the bench times both assemblies.
  const Result alone = cps("bench --quick --threads 2", dir);
  CHECK(alone.exit_code == 2);
  CHECK(alone.err.find("--scene") != std::string::npos);
  const Result assembly = cps("bench --quick --scene stack --assembly explicit", dir);
  CHECK(assembly.exit_code == 2);
  CHECK(assembly.err.find("--assembly") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("cps bench --growth gives the slopes of the times and rows it prints", "[cli][bench]") {
  const fs::path dir = fresh_dir("bench_growth");
  const Result r = cps("bench --quick --json --growth pyramid --sizes 100,300 --friction 0 --solver coloured-pgs", dir);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json g = nlohmann::json::parse(r.out)["growth_series"];
  INFO(g.dump());
  CHECK(g["family"] == "pyramid_N");
  CHECK(g["assembly"] == "matrix-free");
  CHECK(g["parameters"]["friction"] == "0");
  CHECK(g["parameters"]["solver"] == "coloured-pgs");
  REQUIRE(g["points"].size() == 2);
  const nlohmann::json& a = g["points"][0];
  const nlohmann::json& b = g["points"][1];
  CHECK(a["scene"] == "pyramid_100");
  CHECK(b["scene"] == "pyramid_300");
  // A log-log slope over two points is the ratio of the logarithms' differences.
  const auto slope = [&](const char* key) {
    return std::log(b[key].get<double>() / a[key].get<double>()) /
           std::log(b["bodies"].get<double>() / a["bodies"].get<double>());
  };
  CHECK(g["slope_against_bodies"].get<double>() == Approx(slope("us_per_step")).epsilon(1e-9));
  CHECK(g["rows_slope_against_bodies"].get<double>() == Approx(slope("rows_per_step")).epsilon(1e-9));
  CHECK(g["slope_against_rows"].get<double>() ==
        Approx(std::log(b["us_per_step"].get<double>() / a["us_per_step"].get<double>()) /
               std::log(b["rows_per_step"].get<double>() / a["rows_per_step"].get<double>()))
            .epsilon(1e-9));
  for (const nlohmann::json* p : {&a, &b}) {
    CHECK((*p)["us_per_body"].get<double>() ==
          Approx((*p)["us_per_step"].get<double>() / (*p)["bodies"].get<double>()).epsilon(1e-12));
  }
  // The paper's push solves once a step: no relax, so no relax slope; the solve has one.
  CHECK(g["stage_slopes_against_bodies"]["relax"].is_null());
  CHECK(g["stage_slopes_against_bodies"]["solve"].is_number());
  // Bad input is refused before any work, naming what is allowed.
  const auto refused = [&](const std::string& args, const std::string& named) {
    const Result bad = cps(args, dir);
    INFO(args << "\n" << bad.err);
    CHECK(bad.exit_code == 2);
    CHECK(bad.err.find(named) != std::string::npos);
  };
  refused("bench --growth pyramid --sizes 100,100", "two different sizes");
  refused("bench --growth pyramid --sizes 100,30000", "1..20000");
  refused("bench --growth random --sizes 1,2", "pyramid_N");
  refused("bench --sizes 100,300", "--growth");
  refused("bench --growth pyramid --scene stack", "--scene");
  refused("bench --growth pyramid --sizes 100,300 --max-work 1000", "--max-work");
  fs::remove_all(dir);
}

TEST_CASE("cps report never overwrites a foreign report.md, CSV or run.json", "[cli][output]") {
  const fs::path dir = fresh_dir("report_foreign");
  // A complete sweep to merge (the intersecting stack's quick one), computed and timed on one
  // thread; and the same on three threads at once, whose errors, studies and mass ratio table
  // must be the same to the digit (each run and study is computed by one thread alone from the
  // same inputs), only the times differ.
  REQUIRE(cps("report intersecting_stack --quick --jobs 1 --out src", dir).exit_code == 0);
  REQUIRE(cps("report intersecting_stack --quick --jobs 3 --out threads", dir).exit_code == 0);
  for (const char* file : {"intersecting_stack.csv", "mass_ratio.csv",
                           "intersecting_stack_solver_error.csv", "intersecting_stack_references.csv",
                           "intersecting_stack_energy.csv"}) {
    INFO(file);
    const cli_test::CsvRows one = cli_test::read_report_csv(dir / "src" / file);
    const cli_test::CsvRows three = cli_test::read_report_csv(dir / "threads" / file);
    REQUIRE(one.rows.size() == three.rows.size());
    REQUIRE(!one.rows.empty());
    CHECK(one.columns == three.columns);
    for (std::size_t i = 0; i < one.rows.size(); ++i) {
      for (const auto& [column, cell] : one.rows[i]) {
        const bool timed = column.rfind("cpu_s_per_sim_s", 0) == 0 || column == "us_per_step" ||
                           column == "runs_per_repeat" || column == "timing_threads" ||
                           column == "exact_cpu_s";
        if (timed) continue;
        INFO("row " << i << ", " << column);
        CHECK(three.rows[i].at(column) == cell);
      }
    }
    if (std::string(file) == "intersecting_stack.csv") {
      CHECK(one.rows[0].at("timing_threads") == "1");
      CHECK(three.rows[0].at("timing_threads") == "3");
    }
  }
  // Written from the studies' CSVs, the report is the same when merged from them, and the merge
  // steps no world (run.json counts the engine's steps); the sweep stepped every run and study.
  REQUIRE(cps("report --merge src --out merged", dir).exit_code == 0);
  const auto steps = [&](const char* folder) {
    return nlohmann::json::parse(slurp(dir / folder / "run.json"))["engine_steps"].get<std::int64_t>();
  };
  CHECK(steps("merged") == 0);
  CHECK(steps("src") > 100000);
  for (const char* file : {"mass_ratio.csv", "intersecting_stack_solver_error.csv",
                           "intersecting_stack_references.csv", "intersecting_stack_energy.csv",
                           "intersecting_stack.csv", "plots/intersecting_stack_energy.dat",
                           "plots/intersecting_stack_solver_error.dat"}) {
    INFO(file);
    CHECK(slurp(dir / "merged" / file) == slurp(dir / "src" / file));
  }
  // report.md alike but for the load sentence, which only a timed sweep has.
  std::string timed_md = slurp(dir / "src/report.md");
  const std::size_t load = timed_md.find(" Load averages");
  REQUIRE(load != std::string::npos);
  timed_md.erase(load, timed_md.find('\n', load) - load);
  CHECK(slurp(dir / "merged/report.md") == timed_md);
  // Its warm starting table agrees with its CSV (the scene's measure: the largest body speed
  // at the end; the paper's run flings the boxes apart fastest, so few iterations reach it).
  check_warm_table(slurp(dir / "src/report.md"), "intersecting_stack",
                   read_table(dir / "src/intersecting_stack.csv"), "metric.recovery_time_s");
  for (const char* name : {"report.md", "intersecting_stack.csv", "run.json"}) {
    INFO(name);
    const fs::path out = dir / (std::string("out_") + name);
    fs::create_directories(out);
    { std::ofstream(out / name) << "mine\n"; }
    const Result merge = cps("report --merge src --out " + out.filename().string(), dir);
    CHECK(merge.exit_code == 2);
    CHECK(merge.err.find(name) != std::string::npos);
    CHECK(slurp(out / name) == "mine\n");
    CHECK_FALSE(fs::exists(out / "intersecting_stack_trajectory_error_m.png"));
    // The run of one id is refused the same way, before it runs.
    const Result run =
        cps("report --run intersecting_stack.pgs.baumgarte.fixed.it1.ss1 --out " +
                out.filename().string(), dir);
    CHECK(run.exit_code == (std::string(name) == "run.json" ? 2 : 0));
  }
  // --force replaces a same-named foreign file, and run.json then lists what was written.
  const Result forced = cps("report --merge src --out out_report.md --force", dir);
  CHECK(forced.exit_code == 0);
  CHECK(slurp(dir / "out_report.md" / "report.md") != "mine\n");
  const nlohmann::json manifest = nlohmann::json::parse(slurp(dir / "out_report.md" / "run.json"));
  const auto& files = manifest["files"];
  for (const char* name : {"report.md", "intersecting_stack.csv", "mass_ratio.csv"}) {
    INFO(name);
    CHECK(std::find(files.begin(), files.end(), name) != files.end());
  }
  fs::remove_all(dir);
}

TEST_CASE("cps simulate --expect-hash exits 1 on another state, 0 on the same", "[cli][state_hash]") {
  const fs::path dir = fresh_dir("hash");
  const Result first = cps("simulate funnel --seconds 0.5 --json", dir);
  REQUIRE(first.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(first.out);
  const std::string hash = j["state_hash"];
  CHECK(hash.size() == 16);
  CHECK(hash.find_first_not_of("0123456789abcdef") == std::string::npos);
  CHECK(!j["engine_version"].get<std::string>().empty());
  // The same run again ends in the same state.
  CHECK(cps("simulate funnel --seconds 0.5 --expect-hash " + hash, dir).exit_code == 0);
  // Any other hash: exit 1, both hashes printed.
  std::string wrong = hash;
  wrong[15] = wrong[15] == '0' ? '1' : '0';
  const Result differs = cps("simulate funnel --seconds 0.5 --expect-hash " + wrong, dir);
  CHECK(differs.exit_code == 1);
  CHECK(differs.err.find(hash) != std::string::npos);
  CHECK(differs.err.find(wrong) != std::string::npos);
  // One more step is another state.
  CHECK(cps("simulate funnel --seconds 0.52 --expect-hash " + hash, dir).exit_code == 1);
  // Not a hash: a usage error.
  const Result bad = cps("simulate funnel --seconds 0.5 --expect-hash 12345", dir);
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.find("--expect-hash 12345") != std::string::npos);
  fs::remove_all(dir);
}

#ifdef CPS_HAVE_RENDERER
TEST_CASE("cps render writes numbered frames of the requested size", "[cli][renderer]") {
  const fs::path dir = fresh_dir("render");
  const Result r = cps("render stack --seconds 0.2 --fps 10 --size 64x48 --out out", dir);
  REQUIRE(r.exit_code == 0);
  CHECK(fs::exists(dir / "out/stack/frame_000000.png"));
  CHECK(fs::exists(dir / "out/stack/frame_000002.png"));
  CHECK(!fs::exists(dir / "out/stack/frame_000003.png"));
  // PNG header: the IHDR chunk holds width and height big-endian at bytes 16..23.
  std::ifstream png(dir / "out/stack/frame_000001.png", std::ios::binary);
  unsigned char header[24] = {};
  png.read(reinterpret_cast<char*>(header), sizeof header);
  const int width = (header[16] << 24) | (header[17] << 16) | (header[18] << 8) | header[19];
  const int height = (header[20] << 24) | (header[21] << 16) | (header[22] << 8) | header[23];
  CHECK(width == 64);
  CHECK(height == 48);
  fs::remove_all(dir);
}
#endif

TEST_CASE("cps report writes CSVs with units and plots and report.md and runs spread and merge",
          "[cli][report]") {
  const fs::path dir = fresh_dir("report");
  SECTION("one id, run on its own, then merged with another: an INCOMPLETE report, exit 1") {
    const char* ids[] = {"stack.pgs.split.fixed.it4.ss1", "stack.jacobi.split.fixed.it4.ss1"};
    for (const char* id : ids) {
      const Result r = cps(std::string("report stack --run ") + id + " --out runs --quick", dir);
      REQUIRE(r.exit_code == 0);
      CHECK(fs::exists(dir / "runs" / (std::string(id) + ".csv")));
    }
    // Timed by the quick sweep's default 3 repeats (--repeats), the least repeat under the
    // first quartile, the median between the quartiles.
    const auto timed = read_table(dir / "runs/stack.pgs.split.fixed.it4.ss1.csv").at(0);
    CHECK(value(timed, "timing_repeats") == 3);
    CHECK(value(timed, "cpu_s_per_sim_s_min") <= value(timed, "cpu_s_per_sim_s_q1"));
    CHECK(value(timed, "cpu_s_per_sim_s_q1") <= value(timed, "cpu_s_per_sim_s"));
    CHECK(value(timed, "cpu_s_per_sim_s") <= value(timed, "cpu_s_per_sim_s_q3"));
    const Result merged = cps("report --merge runs --out merged", dir);
    // 2 of the quick stack sweep's runs: the others are named (a few, then a count), the studies
    // first (the stack's three, and a row of the mass ratio table per push and solver it reads).
    const int planned = kQuickRuns + 3 + mass_ratio_studies();
    CHECK(merged.exit_code == 1);
    CHECK(merged.err.find(std::to_string(planned - 2) + " of the " + std::to_string(planned) +
                          " planned runs are missing") != std::string::npos);
    CHECK(merged.err.find("stack.solver_error, stack.references, stack.energy") != std::string::npos);
    CHECK(merged.err.find("and " + std::to_string(planned - 2 - 5) + " more") != std::string::npos);
    CHECK(merged.err.find("INCOMPLETE") != std::string::npos);
    const std::string md = slurp(dir / "merged/report.md");
    CHECK(md.find("INCOMPLETE") < md.find("## Headline"));
    // report.md names the first 20 in plan order.
    CHECK(md.find("`stack.energy`") != std::string::npos);
    CHECK(md.find("`mass_ratio.10.pgs.baumgarte`") != std::string::npos);
    const std::string csv = slurp(dir / "merged/stack.csv");
    const std::vector<std::string> columns = cli_test::read_report_csv(dir / "merged/stack.csv").columns;
    for (const char* column : {"cpu_s_per_sim_s", "cpu_s_per_sim_s_q1", "cpu_s_per_sim_s_q3",
                               "timing_repeats", "runs_per_repeat", "machine", "build"}) {
      CHECK(std::find(columns.begin(), columns.end(), column) != columns.end());
    }
    CHECK(csv.find("residual_rms_N") != std::string::npos);
    CHECK(csv.find("penetration_max_m") != std::string::npos);
    CHECK(std::count(csv.begin(), csv.end(), '\n') == 3);  // header and two runs
    CHECK(fs::file_size(dir / "merged/stack_residual_rms_N.png") > 1000);
    CHECK(fs::exists(dir / "merged/stack_residual_rms_N.svg"));
    // And a PDF of it (gnuplot's pdfcairo) beside the PNG, for a paper.
    CHECK(slurp(dir / "merged/stack_residual_rms_N.pdf").substr(0, 5) == "%PDF-");
  }
  SECTION("--list-runs prints one command per run; all of them merge into a complete report") {
    const Result r = cps("report mass_ratio_10 --quick --list-runs --out o", dir);
    REQUIRE(r.exit_code == 0);
    // The error runs, the mass ratio table's rows (a stress scene has no scene studies) and the
    // merge line.
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == kQuickRuns + mass_ratio_studies() + 1);
    CHECK(r.out.find("--run mass_ratio_10.pgs.baumgarte.fixed.it25.ss1 ") != std::string::npos);
    CHECK(r.out.find("--run mass_ratio_10.pgs.baumgarte.fixed.it16.ss1.ws0.8 ") != std::string::npos);
    CHECK(r.out.find("--merge") != std::string::npos);
    std::stringstream lines(r.out);
    int ran = 0;
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("#", 0) == 0) continue;
      const std::string command = "cd '" + dir.string() + "' && " + line + " > /dev/null 2>&1";
      CHECK(std::system(command.c_str()) == 0);
      ++ran;
    }
    CHECK(ran == kQuickRuns + mass_ratio_studies());
    // A warm run's file is named by its id, which reads back to the run: warm_start 0.8.
    const auto warm = read_table(dir / "o/runs/mass_ratio_10.pgs.baumgarte.fixed.it16.ss1.ws0.8.csv");
    REQUIRE(warm.size() == 1u);
    CHECK(warm[0].at("warm_start") == "0.8");
    CHECK(warm[0].at("iterations") == "16");
    const Result merged = cps("report --merge o/runs --out o", dir);
    CHECK(merged.exit_code == 0);
    CHECK(merged.err.find("missing") == std::string::npos);
    CHECK(slurp(dir / "o/report.md").find("INCOMPLETE") == std::string::npos);
  }
  SECTION("a malformed run id is a usage error") {
    const Result r = cps("report --run stack.pgs.sideways.fixed.it4.ss1 --out o", dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("unknown push 'sideways'") != std::string::npos);
    CHECK(!fs::exists(dir / "o"));
  }
  fs::remove_all(dir);
}

TEST_CASE("cps report --shard: the shards of a sweep take every run once and merge into the "
          "sweep's errors for 1 and 7 shards in any order",
          "[cli][report]") {
  const fs::path dir = fresh_dir("report-shard");
  write_drop_scene(dir / "drop.json");
  const Result listed = cps("report drop.json --quick --list-runs --out l", dir);
  REQUIRE(listed.exit_code == 0);
  const auto planned = static_cast<std::size_t>(std::count(listed.out.begin(), listed.out.end(), '\n') - 1);
  REQUIRE(planned > 7u);
  // Of which studies (the mass ratio table's rows: a scene file has no scene studies); the rest
  // are the error runs, a row each of drop.csv.
  std::size_t studies = 0;
  for (std::size_t at = 0; (at = listed.out.find(" --run mass_ratio.", at)) != std::string::npos; ++at) ++studies;
  REQUIRE(studies > 0u);
  const std::size_t error_runs = planned - studies;
  // The run CSVs in `folder` (run.json aside).
  const auto run_files = [&](const fs::path& folder) {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir / folder)) {
      if (entry.path().extension() == ".csv") names.insert(entry.path().filename().string());
    }
    return names;
  };
  // Shards 7 of 7 down to 1, into one folder: each adds the runs its place in the plan gives it
  // and no other shard took, and together they take the plan. One shard of one takes it all.
  std::set<std::string> taken;
  std::set<std::string> second;  // shard 2/7's runs
  for (int shard = 7; shard >= 1; --shard) {
    const Result r = cps("report drop.json --quick --shard " + std::to_string(shard) + "/7 --out s7", dir);
    REQUIRE(r.exit_code == 0);
    std::set<std::string> added;
    for (const std::string& name : run_files("s7")) {
      if (!taken.count(name)) added.insert(name);
    }
    CHECK(added.size() == (planned - static_cast<std::size_t>(shard - 1) + 6) / 7);
    if (shard == 2) second = added;
    taken.insert(added.begin(), added.end());
  }
  CHECK(taken.size() == planned);
  REQUIRE(cps("report drop.json --quick --shard 1/1 --out s1", dir).exit_code == 0);
  CHECK(run_files("s1") == run_files("s7"));
  // Merged: the same runs with the same errors (every cell but the timing's, which measures this
  // machine at that moment).
  REQUIRE(cps("report --merge s1 --out m1", dir).exit_code == 0);
  REQUIRE(cps("report --merge s7 --out m7", dir).exit_code == 0);
  const cli_test::CsvRows one = cli_test::read_report_csv(dir / "m1/drop.csv");
  const cli_test::CsvRows seven = cli_test::read_report_csv(dir / "m7/drop.csv");
  REQUIRE(one.columns == seven.columns);
  REQUIRE(one.rows.size() == error_runs);
  REQUIRE(seven.rows.size() == error_runs);
  CHECK(slurp(dir / "m1/mass_ratio.csv") == slurp(dir / "m7/mass_ratio.csv"));
  CHECK(read_table(dir / "m1/mass_ratio.csv").size() == studies);
  const std::set<std::string> timing = {"cpu_s_per_sim_s", "cpu_s_per_sim_s_q1", "cpu_s_per_sim_s_q3",
                                        "cpu_s_per_sim_s_min", "us_per_step", "runs_per_repeat",
                                        "timing_threads"};
  std::size_t compared = 0;
  for (std::size_t k = 0; k < error_runs; ++k) {
    for (const std::string& column : one.columns) {
      if (timing.count(column)) continue;
      INFO("row " << k << ", column " << column);
      CHECK(one.rows[k].at(column) == seven.rows[k].at(column));
      ++compared;
    }
  }
  CHECK(compared > error_runs * 20);
  // A shard's place from a Slurm job array's variables: task 6 of an array 4, 6, 8, ... of 7
  // tasks is shard 2/7.
  const Result slurm = run_cps("report drop.json --quick --shard slurm --out sl", dir,
                               "SLURM_ARRAY_TASK_ID=6 SLURM_ARRAY_TASK_MIN=4 SLURM_ARRAY_TASK_STEP=2 "
                               "SLURM_ARRAY_TASK_COUNT=7");
  REQUIRE(slurm.exit_code == 0);
  CHECK(slurm.out.find("shard 2/7") != std::string::npos);
  CHECK(run_files("sl") == second);
  const Result outside = run_cps("report drop.json --quick --shard slurm --out so", dir,
                             "env -u SLURM_ARRAY_TASK_ID");
  CHECK(outside.exit_code == 2);
  CHECK(outside.err.find("SLURM_ARRAY_TASK_ID is not set") != std::string::npos);
  CHECK(!fs::exists(dir / "so"));
  fs::remove_all(dir);
}

TEST_CASE("cps report --list-runs quotes every word for sh: names with quotes, spaces, $ and "
          "backticks run where they name, and a control character is refused",
          "[cli][report]") {
  const fs::path dir = fresh_dir("report-quoting");
  // A scene file whose name holds a space and a quote, and output folders a shell would misread.
  const std::string scene = "my drop's.json";
  write_drop_scene(dir / scene);
  for (const std::string out : {"x'; touch PWNED; echo '", "O'Brien runs", "$HOME and `touch TICK`",
                                "a \"b\" \\c"}) {
    INFO("--out " << out);
    // The names travel through files, so that the test's own command line needs no quoting.
    { std::ofstream(dir / "out.txt") << out; }
    { std::ofstream(dir / "scene.txt") << scene; }
    const Result listed = cps("report \"$(cat scene.txt)\" --quick --list-runs --out \"$(cat out.txt)\"", dir);
    REQUIRE(listed.exit_code == 0);
    std::vector<std::string> lines;
    std::stringstream text(listed.out);
    for (std::string line; std::getline(text, line);) lines.push_back(line);
    REQUIRE(lines.size() > 3u);
    // Two listed runs, run by sh: their CSVs land in OUT/runs under the names cps gives them.
    for (std::size_t k = 0; k < 2; ++k) {
      const std::string command = "cd '" + dir.string() + "' && sh -c \"$(sed -n " +
                                  std::to_string(k + 1) + "p stdout.list)\" > /dev/null 2>&1";
      { std::ofstream(dir / "stdout.list") << listed.out; }
      CHECK(std::system(command.c_str()) == 0);
    }
    std::size_t csvs = 0;
    if (fs::is_directory(dir / out / "runs")) {
      for (const auto& e : fs::directory_iterator(dir / out / "runs")) csvs += e.path().extension() == ".csv";
    }
    CHECK(csvs == 2u);
    CHECK(!fs::exists(dir / "PWNED"));
    CHECK(!fs::exists(dir / "TICK"));
    // The merge line, its comment mark taken off and cps's path replaced by printf: sh reads
    // exactly the words report --merge OUT/runs --out OUT.
    const std::string& merge = lines.back();
    const std::string mark = "# when all have finished: ";
    REQUIRE(merge.rfind(mark, 0) == 0);
    const std::size_t words = merge.find(" report --merge ");
    REQUIRE(words != std::string::npos);
    { std::ofstream(dir / "merge.sh") << "printf '[%s]\\n'" << merge.substr(words) << "\n"; }
    const std::string read_back = "cd '" + dir.string() + "' && sh merge.sh > merge.out";
    REQUIRE(std::system(read_back.c_str()) == 0);
    CHECK(slurp(dir / "merge.out") ==
          "[report]\n[--merge]\n[" + out + "/runs]\n[--out]\n[" + out + "]\n");
    fs::remove_all(dir / out);
  }
  // A newline cannot stay inside a listing of one command a line: refused, naming it.
  { std::ofstream(dir / "out.txt") << "two\nlines"; }
  const Result newline = cps("report \"$(cat scene.txt)\" --quick --list-runs --out \"$(cat out.txt)\"", dir);
  CHECK(newline.exit_code == 2);
  CHECK(newline.err.find("--out holds the control character 0x0a") != std::string::npos);
  CHECK(newline.out.empty());
  fs::remove_all(dir);
}

TEST_CASE("cps report --repeats sets the timed repeats, their quartiles and what they ran on",
          "[cli][report]") {
  const fs::path dir = fresh_dir("report_repeats");
  const std::string id = "stack.pgs.split.fixed.it4.ss1";
  SECTION("a run with --repeats 3: three repeats, Q1 <= median <= Q3, machine and build recorded") {
    REQUIRE(cps("report stack --run " + id + " --repeats 3 --out runs", dir).exit_code == 0);
    const auto row = read_table(dir / "runs" / (id + ".csv")).at(0);
    CHECK(value(row, "timing_repeats") == 3);
    CHECK(value(row, "runs_per_repeat") >= 1);
    CHECK(value(row, "cpu_s_per_sim_s_q1") > 0.0);
    CHECK(value(row, "cpu_s_per_sim_s_q1") <= value(row, "cpu_s_per_sim_s"));
    CHECK(value(row, "cpu_s_per_sim_s") <= value(row, "cpu_s_per_sim_s_q3"));
    CHECK(value(row, "us_per_step") > 0.0);
    CHECK(row.at("machine").find("logical CPU") != std::string::npos);
    CHECK(!row.at("build").empty());
    const nlohmann::json info = nlohmann::json::parse(slurp(dir / "runs/run.json"));
    CHECK(info.dump().find("\"repeats\":3") != std::string::npos);
    CHECK(info.dump().find("CLOCK_THREAD_CPUTIME_ID") != std::string::npos);
    CHECK(info.dump().find(row.at("machine")) != std::string::npos);
    CHECK(info.dump().find(row.at("build")) != std::string::npos);
  }
  SECTION("--list-runs passes --repeats on to every run's command, and only a value not the default") {
    const Result seven = cps("report stack --quick --list-runs --repeats 7 --out o", dir);
    REQUIRE(seven.exit_code == 0);
    std::stringstream lines(seven.out);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("#", 0) != 0) CHECK(line.find(" --repeats 7") != std::string::npos);
    }
    const Result plain = cps("report stack --quick --list-runs --out o", dir);
    REQUIRE(plain.exit_code == 0);
    CHECK(plain.out.find("--repeats") == std::string::npos);
  }
  SECTION("a bad --repeats, and repeats past the work budget, are refused naming the value and range") {
    const std::vector<Case> cases = {
        {"report stack --run " + id + " --repeats 2 --out out", "'2': timed repeats per run must be in [3, 100]"},
        {"report stack --run " + id + " --repeats 101 --out out", "'101': timed repeats per run must be in [3, 100]"},
        {"report stack --quick --repeats 0 --out out", "'0': timed repeats per run must be in [3, 100]"},
        {"report stack --quick --repeats -5 --out out", "'-5'"},
        {"report stack --quick --repeats 4.5 --out out", "'4.5' is not a whole number; give a count of timed repeats in [3, 100]"},
        {"report stack --quick --repeats five --out out", "'five' is not a whole number"},
        {"report stack --quick --repeats 1e2 --out out", "'1e2' is not a whole number"},
        {"report stack --quick --repeats '' --out out", "'' is not a whole number"},
        {"report stack --quick --repeats 99999999999 --out out", "'99999999999'"},
        {"report push --repeats 7 --out out", "--repeats applies to the sweeps"},
        // The run is 6 bodies x 600 steps x 4 iterations = 14400 body-iterations: its 5 repeats,
        // the error run and the warm-up are 7 x 14400, over a budget of 1e5.
        {"report stack --run " + id + " --max-work 100000 --out out",
         "7 x 14400 = 100800 body-iterations"},
    };
    expect_refused(cases, dir);
  }
}

TEST_CASE("cps report plans warm-started PGS runs beside the cold sweep and their ids read back",
          "[cli][report]") {
  const fs::path dir = fresh_dir("warm_plan");
  // A study's id: a paper scene's three, or a row of the mass ratio table.
  const auto is_study = [](const std::string& id) {
    return id.rfind("mass_ratio.", 0) == 0 || id.ends_with(".solver_error") ||
           id.ends_with(".references") || id.ends_with(".energy");
  };
  // The ids of a sweep's plan, from --list-runs: its error runs, or with `studies` its studies.
  const auto ids_of = [&](const std::string& args, bool studies = false) {
    const Result r = cps("report " + args + " --list-runs --out o", dir);
    REQUIRE(r.exit_code == 0);
    std::vector<std::string> ids;
    std::stringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) {
      const std::size_t at = line.find("--run ");
      if (at == std::string::npos) continue;
      const std::string id = line.substr(at + 6, line.find(' ', at + 6) - at - 6);
      if (is_study(id) == studies) ids.push_back(id);
    }
    return ids;
  };
  SECTION("the studies come first: the scene's three, then a row of the mass ratio table each") {
    const Result r = cps("report funnel --quick --list-runs --out o", dir);
    REQUIRE(r.exit_code == 0);
    const std::vector<std::string> studies = ids_of("funnel --quick", true);
    REQUIRE(studies.size() == static_cast<std::size_t>(3 + mass_ratio_studies()));
    CHECK(studies[0] == "funnel.solver_error");
    CHECK(studies[1] == "funnel.references");
    CHECK(studies[2] == "funnel.energy");
    CHECK(studies[3] == "mass_ratio.10.pgs.baumgarte");
    CHECK(r.out.find(studies.back()) < r.out.find(ids_of("funnel --quick").front()));
    // A scene file has no scene studies; the mass ratio rows are in every plan.
    CHECK(ids_of("stress --quick", true).size() == static_cast<std::size_t>(mass_ratio_studies()));
  }
  // The factor of an id (after ".ws"; 0 without) and whether it is PGS at 1 substep.
  const auto factor = [](const std::string& id) {
    const std::size_t ws = id.rfind(".ws");
    return ws == std::string::npos ? 0.0 : std::stod(id.substr(ws + 3));
  };
  SECTION("quick: the cold sweep and PGS, Baumgarte, fixed friction at 0.8 and 1, it 1, 4, 16, 25") {
    const std::vector<std::string> ids = ids_of("funnel --quick");
    CHECK(ids.size() == static_cast<std::size_t>(kQuickRuns));
    std::map<double, std::vector<std::string>> by_factor;
    for (const std::string& id : ids) by_factor[factor(id)].push_back(id);
    CHECK(by_factor[0.0].size() == static_cast<std::size_t>(kQuickCold));
    for (const double w : {0.8, 1.0}) {
      INFO("warm start " << w);
      std::vector<std::string> expected;
      for (const int it : {1, 4, 16, 25}) {
        std::ostringstream id;
        id << "funnel.pgs.baumgarte.fixed.it" << it << ".ss1.ws" << w;
        expected.push_back(id.str());
      }
      CHECK(by_factor[w] == expected);
    }
    CHECK(by_factor.size() == 3u);
  }
  SECTION("full: every push and friction model, PGS's whole iteration line at 0.8 and 1") {
    const std::vector<std::string> ids = ids_of("funnel");
    // The funnel has friction: friction models fixed and coupled. Cold: 10 iteration counts at
    // 1 substep and 4 substep counts at 25 iterations, per solver, push and friction model.
    // Warm: 10 iteration counts per factor, push and friction model, PGS only. A push method
    // runs only the solvers, friction models and warm starts it reads (cps::push_reads).
    int cold = 0;
    int warm = 0;
    for (const cli_test::Reads& r : cli_test::push_method_reads()) {
      const int frictions = r.friction_model ? 2 : 1;
      cold += (10 + 4) * (r.solver ? 2 : 1) * frictions;
      warm += r.warm_start ? 2 * 10 * frictions : 0;
    }
    CHECK(ids.size() == static_cast<std::size_t>(cold + warm));
    // No run repeats another under a setting its push does not read.
    const std::vector<std::string> names = cli_test::push_method_names();
    const std::vector<cli_test::Reads> reads = cli_test::push_method_reads();
    for (std::size_t m = 0; m < names.size(); ++m) {
      for (const std::string& id : ids) {
        if (id.find("." + names[m] + ".") == std::string::npos) continue;
        INFO(id);
        if (!reads[m].solver) CHECK(id.find(".jacobi.") == std::string::npos);
        if (!reads[m].friction_model) CHECK(id.find(".coupled.") == std::string::npos);
        if (!reads[m].warm_start) CHECK(factor(id) == 0.0);
      }
    }
    int n_warm = 0;
    for (const std::string& id : ids) {
      if (factor(id) == 0.0) continue;
      ++n_warm;
      INFO(id);
      CHECK(id.find(".pgs.") != std::string::npos);
      CHECK(id.find(".ss1.ws") != std::string::npos);
      CHECK((factor(id) == 0.8 || factor(id) == 1.0));
    }
    CHECK(n_warm == warm);
    // Every push method of the table enters the sweep, in the table's order (its first run of
    // each method comes after the first run of the method before it).
    std::size_t last = 0;
    for (const std::string& method : cli_test::push_method_names()) {
      const std::string part = "." + method + ".";
      const auto at = std::find_if(ids.begin(), ids.end(),
                                   [&](const std::string& id) { return id.find(part) != std::string::npos; });
      INFO(method);
      REQUIRE(at != ids.end());
      CHECK(static_cast<std::size_t>(at - ids.begin()) >= last);
      last = static_cast<std::size_t>(at - ids.begin());
    }
    for (const char* id : {"funnel.pgs.split.coupled.it256.ss1.ws1", "funnel.pgs.baumgarte.fixed.it2.ss1.ws0.8"}) {
      CHECK(std::find(ids.begin(), ids.end(), id) != ids.end());
    }
  }
  SECTION("an id runs the run it names; .ws0 is the cold run, named without it") {
    const std::string cold = "intersecting_stack.pgs.baumgarte.fixed.it4.ss1";
    REQUIRE(cps("report intersecting_stack --run " + cold + ".ws0 --out r", dir).exit_code == 0);
    const auto c = read_table(dir / "r" / (cold + ".csv"));
    REQUIRE(c.size() == 1u);
    CHECK(c[0].at("warm_start") == "0");
    REQUIRE(cps("report intersecting_stack --run " + cold + ".ws1 --out r", dir).exit_code == 0);
    const auto w = read_table(dir / "r" / (cold + ".ws1.csv"));
    REQUIRE(w.size() == 1u);
    CHECK(w[0].at("warm_start") == "1");
    CHECK(w[0].at("iterations") == "4");
    CHECK(w[0].at("solver") == "pgs");
  }
  fs::remove_all(dir);
}

TEST_CASE("cps report's mass ratio table says whether each stack held", "[cli][report]") {
  const fs::path dir = fresh_dir("held");
  // The table's rows are studies of every sweep's plan: each run alone by its id, as listed.
  const Result listed = cps("report stack --list-runs --out l", dir);
  REQUIRE(listed.exit_code == 0);
  std::istringstream lines(listed.out);
  int studies = 0;
  for (std::string line; std::getline(lines, line);) {
    const std::size_t at = line.find(" --run mass_ratio.");
    if (at == std::string::npos) continue;
    const std::string id = line.substr(at + 7, line.find(' ', at + 7) - at - 7);
    REQUIRE(cps("report --run " + id + " --out runs", dir).exit_code == 0);
    ++studies;
  }
  REQUIRE(cps("report --run stack.pgs.split.fixed.it4.ss1 --out runs", dir).exit_code == 0);
  // Incomplete (exit 1: the stack's other runs are missing), but with the whole table.
  const Result merged = cps("report --merge runs --out r", dir);
  CHECK(merged.exit_code == 1);
  CHECK(merged.err.find("mass_ratio.") == std::string::npos);
  const auto rows = read_table(dir / "r/mass_ratio.csv");
  CHECK(rows.size() == static_cast<std::size_t>(studies));
  REQUIRE(rows.size() == static_cast<std::size_t>(mass_ratio_studies()));
  // Cubes of edge 1 m: stacked, the heavy one's centre is at 1.5 m; squeezed out, at 0.5 m.
  const double h = 0.5;
  for (const auto& row : rows) {
    INFO(row.at("mass_ratio") << " " << row.at("solver") << " " << row.at("push"));
    const double offset = value(row, "light_offset_m");
    const double height = value(row, "heavy_height_m");
    // The stated definition: the light cube's centre within its half edge of the heavy cube's
    // axis, the heavy cube within h / 2 of its stacked height.
    const bool held = offset <= h && std::abs(height - 3.0 * h) <= 0.5 * h;
    CHECK((row.at("held") == "1") == held);
  }
  const auto pair = [&](const std::string& ratio, const std::string& solver, const std::string& push) {
    for (const auto& row : rows) {
      if (row.at("mass_ratio") == ratio && row.at("solver") == solver && row.at("push") == push) return row;
    }
    FAIL("no row " << ratio << " " << solver << " " << push);
    return rows.front();
  };
  // Ratio 10: PGS converges by rho = R / (1 + R) = 0.91 per sweep; 25 sweeps hold the light
  // cube in place (the 1D model needs about 4; the 3D pair about 16).
  const auto ten = pair("10", "pgs", "baumgarte");
  CHECK(ten.at("held") == "1");
  CHECK(value(ten, "heavy_height_m") == Approx(1.5).margin(0.05));
  CHECK(value(ten, "light_offset_m") < 0.1);
  // Ratio 1000: rho = 0.999, 25 sweeps leave the ground row most of the load unsolved; the light
  // cube is walked out from under the heavy one, which lands on the ground.
  const auto thousand = pair("1000", "pgs", "baumgarte");
  CHECK(thousand.at("held") == "0");
  CHECK(value(thousand, "light_offset_m") > h);
  CHECK(value(thousand, "heavy_height_m") == Approx(h).margin(0.05));
  fs::remove_all(dir);
}

TEST_CASE("the exact solve opens Siconos when it first runs: without the library --solver-error "
          "fails naming it, and every other run works", "[cli][exact]") {
  // cps is not linked against Siconos numerics (dlopen on the first exact solve);
  // CPS_SICONOS_LIBRARY names one that is not there.
  const fs::path dir = cli_test::fresh_dir("cps-test-siconos-nolib");
  const std::string missing = "CPS_SICONOS_LIBRARY=libcps-test-no-such-siconos.so.7";
  const std::string with_errors = "simulate stack --seconds 0.6 --at 30 --solver-error out/e.csv";
  const Result r = run_cps(with_errors, dir, missing);
  INFO(r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("libcps-test-no-such-siconos.so.7") != std::string::npos);
  CHECK(r.err.find("libsiconos-numerics7") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "out" / "e.csv"));
  const Result plain = run_cps("simulate stack --seconds 0.6", dir, missing);
  CHECK(plain.exit_code == 0);
  // With the library found (the SONAME from configure time), the same run solves step 30 exactly.
  const Result found = run_cps(with_errors, dir);
  INFO(found.err);
  CHECK(found.exit_code == 0);
  // Its row: the exact solution solves the LCP, so its natural map residual is round-off, far
  // under the 1e-9 of the force scale solve_exact accepts (the stack's forces are under 1e3 N).
  // NaN fails these checks.
  int exact_rows = 0;
  for (const auto& row : read_table(dir / "out" / "e.csv")) {
    if (row.at("method") != "exact") continue;
    ++exact_rows;
    CHECK(value(row, "step") == 30);
    CHECK(value(row, "natural_map_N") <= 1e-6);
    CHECK(value(row, "signorini_velocity_mps") <= 1e-9);
  }
  CHECK(exact_rows == 1);
  // Beside it, e-rows.csv: every row of the solve with its bounds and the least-norm exact
  // lambda, inside its bounds, whose norm is the |lambda*| the CSV's relative errors divide by
  // (lambda_error_N / lambda_error_relative of the engine's row).
  const auto errors = read_table(dir / "out" / "e.csv");
  const auto rows = read_table(dir / "out" / "e-rows.csv");
  REQUIRE(!rows.empty());
  CHECK(static_cast<double>(rows.size()) == value(errors.at(0), "rows"));
  double norm_sq = 0.0;
  for (const auto& row : rows) {
    CHECK(value(row, "step") == 30);
    const double lambda = value(row, "lambda_exact_N");
    CHECK(lambda >= value(row, "c_min_N") - 1e-9 * std::max(1.0, std::abs(lambda)));
    CHECK(lambda <= value(row, "c_max_N") + 1e-9 * std::max(1.0, std::abs(lambda)));
    norm_sq += lambda * lambda;
  }
  for (const auto& row : errors) {
    if (row.at("method") != "engine") continue;
    REQUIRE(value(row, "lambda_error_relative") > 0.0);
    CHECK(std::sqrt(norm_sq) ==
          Approx(value(row, "lambda_error_N") / value(row, "lambda_error_relative")).epsilon(1e-6));
  }
  fs::remove_all(dir);
}
