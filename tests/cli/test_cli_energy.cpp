// cps simulate --energy, run as a user runs it: the columns and their units, the first row against
// the start energy computed here from the scene, the energy's drift per step against semi-implicit
// Euler's closed form, every push method on a scene file, and the values it refuses.
#include "cli_support.h"
#include "push_methods.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cli_test::fresh_dir;
using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;

namespace {

// The columns of an energy CSV, with their units (docs/commands.md, simulate).
const std::vector<std::string> kColumns = {"step",    "t_s",           "kinetic_J",  "potential_J",
                                           "total_J", "penetration_m", "rod_error_m"};

// A CSV: its header and its rows of numbers.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
};

Csv read_csv(const fs::path& p) {
  Csv csv;
  std::ifstream in(p);
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string cell;
    std::vector<std::string> cells;
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    if (first) {
      csv.header = cells;
      first = false;
      continue;
    }
    std::vector<double> row;
    for (const std::string& c : cells) row.push_back(std::stod(c));
    csv.rows.push_back(row);
  }
  return csv;
}

void write_text(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// One box in free fall, spinning about a principal axis, no ground: mass m (kg), half extents
// (hx, hy, hz) (m), centre x0 (m), velocity v0 (m/s), angular velocity (0, 0, wz) (rad/s), under
// the default gravity (0, -g, 0) with g = 10 m/s^2 and dt = 1/60 s.
struct FreeFall {
  double m = 2.0;
  double hx = 0.5, hy = 0.2, hz = 0.3;
  double x0[3] = {1.0, 50.0, -2.0};
  double v0[3] = {0.5, 3.0, -1.0};
  double wz = 2.0;
  double g = 10.0;
  double dt = 1.0 / 60.0;

  std::string scene_file() const {
    std::ostringstream s;
    s.precision(17);
    s << R"({"name": "fall", "seconds": 1, "world": {"dt_s": )" << dt << R"(}, "bodies": [)"
      << R"({"shape": "box", "half_extents_m": [)" << hx << ", " << hy << ", " << hz
      << R"(], "mass_kg": )" << m << R"(, "position_m": [)" << x0[0] << ", " << x0[1] << ", "
      << x0[2] << R"(], "velocity_mps": [)" << v0[0] << ", " << v0[1] << ", " << v0[2]
      << R"(], "angular_velocity_radps": [0, 0, )" << wz << "]}]}";
    return s.str();
  }
  // The start's energy (J): 1/2 m |v0|^2 + 1/2 I_zz wz^2 with I_zz = m (hx^2 + hy^2) / 3 (a
  // solid box about its z axis), and the potential m g y0 (datum y = 0).
  double kinetic() const {
    const double izz = m * (hx * hx + hy * hy) / 3.0;
    return 0.5 * m * (v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]) + 0.5 * izz * wz * wz;
  }
  double potential() const { return m * g * x0[1]; }
};

}  // namespace

TEST_CASE("cps simulate --energy: the first row is the start's energy and a free fall loses "
          "m g^2 dt^2 / 2 a step",
          "[cli][energy]") {
  const fs::path dir = fresh_dir("energy_fall");
  const FreeFall f;
  write_text(dir / "fall.json", f.scene_file());
  const Result r = run_cps("simulate fall.json --seconds 1 --energy e.csv", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const Csv csv = read_csv(dir / "e.csv");
  CHECK(csv.header == kColumns);
  const long steps = std::lround(1.0 / f.dt);
  REQUIRE(csv.rows.size() == static_cast<std::size_t>(steps + 1));
  // Row 0 is the scene as built, computed here from the file's numbers.
  const std::vector<double>& first = csv.rows.front();
  CHECK(first[0] == 0.0);
  CHECK(first[1] == 0.0);
  CHECK(first[2] == Approx(f.kinetic()).epsilon(1e-10));
  CHECK(first[3] == Approx(f.potential()).epsilon(1e-10));
  CHECK(first[4] == Approx(f.kinetic() + f.potential()).epsilon(1e-10));
  // The drift. Semi-implicit Euler (Eqs. 3.2.1-3.2.3) gives v_k = v0 - g k dt, the exact
  // velocity at t_k = k dt, and y_k = y0 + v0 t_k - g dt^2 k (k + 1) / 2, which is
  // g dt^2 k / 2 below the exact y(t_k) = y0 + v0 t_k - g t_k^2 / 2. The spin about a principal
  // axis keeps its kinetic energy. So E_k - E_0 = -m g^2 dt^2 k / 2 exactly: the bound
  // |E(t) - E(0)| <= m g^2 dt t / 2 holds with equality. Tolerance: the CSV's 12 digits of ~1e3 J.
  const double e0 = first[4];
  const double printed = 1e-11 * std::abs(e0) * 10.0;  // J
  for (const std::vector<double>& row : csv.rows) {
    const double k = row[0];
    INFO("step " << k);
    REQUIRE(row.size() == kColumns.size());
    CHECK(row[1] == Approx(k * f.dt).margin(1e-9));
    CHECK(row[4] - e0 == Approx(-f.m * f.g * f.g * f.dt * f.dt * k / 2.0).margin(printed));
    CHECK(row[2] + row[3] == Approx(row[4]).margin(printed));
    CHECK(row[5] == 0.0);  // no contact
    CHECK(row[6] == 0.0);  // no rod
  }
  // One row every 7 steps, and the last: steps 0, 7, ..., 56 and 60.
  REQUIRE(run_cps("simulate fall.json --seconds 1 --energy e7.csv --energy-every 7", dir).exit_code == 0);
  const Csv every = read_csv(dir / "e7.csv");
  std::vector<double> listed;
  for (const std::vector<double>& row : every.rows) listed.push_back(row[0]);
  std::vector<double> expected;
  for (long k = 0; k <= steps; k += 7) expected.push_back(static_cast<double>(k));
  if (steps % 7 != 0) expected.push_back(static_cast<double>(steps));
  CHECK(listed == expected);
  // run.json lists both files as cps's.
  const std::string manifest = slurp(dir / "run.json");
  CHECK(manifest.find("\"e.csv\"") != std::string::npos);
  CHECK(manifest.find("\"e7.csv\"") != std::string::npos);
}

TEST_CASE("cps simulate --energy with a scene file of rods under every push method",
          "[cli][energy]") {
  const fs::path dir = fresh_dir("energy_pushes");
  // The Newton's cradle of tests/data: five 1 kg balls on 1 m rods, the first raised 60 degrees
  // (y = 1.5 m), the others at y = 1 m, all at rest: E(0) = m g sum y, with the heights read
  // from the file itself.
  const std::string cradle = slurp(fs::path(CPS_TEST_DATA) / "cradle.json");
  REQUIRE(!cradle.empty());
  write_text(dir / "cradle.json", cradle);
  double start_potential = 0.0;  // J: m g y of each ball, read from its "position_m"
  for (std::size_t at = cradle.find("\"position_m\": ["); at != std::string::npos;
       at = cradle.find("\"position_m\": [", at + 1)) {
    std::stringstream s(cradle.substr(at + 15));
    double x = 0.0, y = 0.0;
    char comma = 0;
    s >> x >> comma >> y;
    start_potential += 1.0 * 10.0 * y;  // mass_kg 1, the default gravity 10 m/s^2
  }
  for (const std::string& push : cli_test::push_method_names()) {
    INFO("--push " << push);
    const Result r = run_cps("simulate cradle.json --seconds 0.5 --push " + push +
                                 " --energy " + push + ".csv",
                             dir);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const Csv csv = read_csv(dir / (push + ".csv"));
    CHECK(csv.header == kColumns);
    REQUIRE(csv.rows.size() == 31u);  // 0.5 s at the default 60 Hz, and the state as built
    CHECK(csv.rows.front()[2] == 0.0);
    CHECK(csv.rows.front()[3] == Approx(start_potential).epsilon(1e-10));
    // The rods are built at their lengths: no error at the start (the file's 17 digits).
    CHECK(csv.rows.front()[6] == Approx(0.0).margin(1e-12));
    for (const std::vector<double>& row : csv.rows) {
      CHECK(row[5] >= 0.0);
      CHECK(row[6] >= 0.0);
      CHECK(std::isfinite(row[4]));
    }
  }
}

TEST_CASE("cps simulate --energy refuses bad values and writes nothing", "[cli][energy]") {
  const fs::path dir = fresh_dir("energy_bad");
  write_text(dir / "lab.csv", "mine\n");
  fs::create_directories(dir / "adir");
  struct Bad {
    std::string args;
    std::string named;  // what the message must name
  };
  const std::vector<Bad> bad = {
      {"--energy ''", "--energy"},
      {"--energy lab.csv", "--force"},
      {"--energy adir", "adir"},
      {"--energy e.csv --energy-every 0", "0"},
      {"--energy e.csv --energy-every -3", "-3"},
      {"--energy e.csv --energy-every 1.5", "1.5"},
      {"--energy e.csv --energy-every 1e3", "1e3"},
      {"--energy e.csv --energy-every 10000001", "10000001"},
      {"--energy-every 2", "--energy"},
      {"--energy e.csv --trace ./e.csv", "--trace"},
      // 1e5 s at dt 0.01 s is 1e7 steps: more rows than an energy file may have.
      {"--energy e.csv --seconds 1e5 --dt 0.01 --max-work 1e18", "--energy-every"},
  };
  for (const Bad& b : bad) {
    const std::string seconds = b.args.find("--seconds") == std::string::npos ? "--seconds 0.1 " : "";
    const Result r = run_cps("simulate stack " + seconds + b.args, dir);
    INFO(b.args << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(b.named) != std::string::npos);
    CHECK(!fs::exists(dir / "e.csv"));
    CHECK(!fs::exists(dir / "run.json"));
    CHECK(slurp(dir / "lab.csv") == "mine\n");
  }
}

TEST_CASE("cps simulate bounds --trace, and replaces another scene's --trace, --energy or "
          "--solver-error file only with --force",
          "[cli][energy][output]") {
  const fs::path dir = fresh_dir("simulate_files");
  // 1e5 s at 1/60 s is 6e6 steps of the stack's 6 bodies: more rows than a trace may have,
  // refused before any step with a --seconds that fits.
  Result r = run_cps("simulate stack --seconds 1e5 --trace t.csv", dir);
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("rows a trace may have; give --seconds") != std::string::npos);
  CHECK(!fs::exists(dir / "t.csv"));
  CHECK(!fs::exists(dir / "run.json"));
  // The trace's rows count in --max-work with the run: the run's 6 x 600 x 25 = 90000
  // body-iterations fit a budget of 92000, with the trace's 601 x 6 = 3606 rows they do not.
  r = run_cps("simulate stack --seconds 10 --trace t.csv --max-work 92000", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("the trace's 3606 rows") != std::string::npos);
  CHECK(fs::is_empty(dir));
  const std::string files = " --seconds 0.1 --trace t.csv --energy e.csv --solver-error s.csv";
  REQUIRE(run_cps("simulate stack" + files, dir).exit_code == 0);
  const std::string stack_trace = slurp(dir / "t.csv");
  // The same scene again replaces its own files; another scene is refused, naming both, and
  // leaves every file as it was, each option alone too.
  CHECK(run_cps("simulate stack" + files, dir).exit_code == 0);
  for (const char* option : {" --trace t.csv", " --energy e.csv", " --solver-error s.csv"}) {
    r = run_cps(std::string("simulate intersecting_stack --seconds 0.1") + option, dir);
    INFO(option << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("scene intersecting_stack") != std::string::npos);
    CHECK(r.err.find("scene stack") != std::string::npos);
    CHECK(r.err.find("--force") != std::string::npos);
  }
  r = run_cps("simulate intersecting_stack" + files, dir);
  CHECK(r.exit_code == 2);
  CHECK(slurp(dir / "t.csv") == stack_trace);
  CHECK(run_cps("simulate intersecting_stack --force" + files, dir).exit_code == 0);
  CHECK(slurp(dir / "t.csv") != stack_trace);
  fs::remove_all(dir);
}

TEST_CASE("cps simulate --solver-error refuses a system past the exact solve's rows, and re-solves "
          "past --max-work, before any is solved and with nothing written",
          "[cli][energy][output]") {
  const fs::path dir = fresh_dir("solver_error_bounds");
  // pyramid_100's contacts give some 2100 rows a step: a dense LCP that Lemke's pivots would
  // take minutes for, refused when the run reaches the step.
  Result r = run_cps("simulate pyramid_100 --seconds 0.1 --solver-error s.csv", dir);
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("rows, more than the 1000 an exact solve takes") != std::string::npos);
  CHECK(fs::is_empty(dir));
  // A million sweeps of the intersecting stack's rows (some 50), three methods: past a budget of
  // 1e6 that the run itself (a few bodies, 6 steps) leaves nearly whole.
  r = run_cps("simulate intersecting_stack --seconds 0.1 --solver-error s.csv --sweeps 1000000 "
              "--max-work 1e6", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--max-work") != std::string::npos);
  CHECK(fs::is_empty(dir));
  // A run that fails after its trace was begun leaves run.json listing only files that exist:
  // none in a new folder (so no run.json), the earlier trace beside it.
  r = run_cps("simulate pyramid_100 --seconds 0.1 --trace t.csv --solver-error s.csv", dir);
  CHECK(r.exit_code == 2);
  CHECK(fs::is_empty(dir));
  REQUIRE(run_cps("simulate stack --seconds 0.1 --trace t.csv", dir).exit_code == 0);
  r = run_cps("simulate pyramid_100 --seconds 0.1 --trace t2.csv --solver-error s.csv", dir);
  CHECK(r.exit_code == 2);
  CHECK(!fs::exists(dir / "t2.csv"));
  const nlohmann::json manifest = nlohmann::json::parse(slurp(dir / "run.json"));
  INFO(manifest.dump(1));
  CHECK(manifest["files"] == nlohmann::json::array({"t.csv"}));
  CHECK(manifest["complete"] == true);
  CHECK(manifest["unfinished_runs"].empty());
  fs::remove(dir / "run.json");
  fs::remove(dir / "t.csv");
  // Within both, the same request writes its files.
  CHECK(run_cps("simulate intersecting_stack --seconds 0.1 --solver-error s.csv --sweeps 100 "
                "--max-work 1e6", dir)
            .exit_code == 0);
  CHECK(fs::exists(dir / "s.csv"));
  fs::remove_all(dir);
}

TEST_CASE("simulate --quiet prints each kind of warning once as one line with its docs page, and "
          "--warnings-as-errors exits 3 when a warning fired, 0 when none did",
          "[cli][energy][warnings]") {
  const fs::path dir = fresh_dir("cps-test-quiet");
  // The cradle of rods under the paper's push gains energy (docs/findings.md): one warning.
  const std::string run = std::string("simulate ") + CPS_TEST_DATA + "/cradle.json --seconds 10 ";
  const auto lines = [](const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
  };
  const Result loud = run_cps(run + "--push baumgarte", dir);
  REQUIRE(loud.exit_code == 0);
  const std::vector<std::string> loud_lines = lines(loud.err);
  REQUIRE(loud_lines.size() == 1u);
  CHECK(loud_lines[0].rfind("cps: warning: ", 0) == 0);
  CHECK(loud_lines[0].size() > 300);  // the whole story: when, how much, the fix to try
  const Result quiet = run_cps(run + "--push baumgarte --quiet", dir);
  REQUIRE(quiet.exit_code == 0);
  const std::vector<std::string> quiet_lines = lines(quiet.err);
  REQUIRE(quiet_lines.size() == 1u);
  CHECK(quiet_lines[0].rfind("cps: warning: ", 0) == 0);
  CHECK(quiet_lines[0].size() < 200);
  // The page it names, and its anchor: a heading of that page.
  const std::string link = "docs/findings.md#energy-that-rises-with-nothing-driving-it";
  CHECK(quiet_lines[0].find("(see " + link + ")") != std::string::npos);
  CHECK(slurp(std::string(CPS_TEST_DATA) + "/../../docs/findings.md")
            .find("\n## Energy that rises with nothing driving it\n") != std::string::npos);
  // --warnings-as-errors: exit 3 after the warning, and says why; the run's summary is printed.
  const Result strict = run_cps(run + "--push baumgarte --quiet --warnings-as-errors", dir);
  CHECK(strict.exit_code == 3);
  CHECK(strict.err.find("--warnings-as-errors") != std::string::npos);
  CHECK(strict.out.find("600 steps") != std::string::npos);
  // Without a warning it changes nothing: the single frame push keeps the cradle's energy.
  const Result kept = run_cps(run + "--push split --warnings-as-errors", dir);
  CHECK(kept.exit_code == 0);
  CHECK(kept.err.find("warning") == std::string::npos);
  // Notes go too: --trace's line ("trace: N rows ...") only without --quiet.
  const std::string traced = "simulate stack --seconds 0.1 --trace t.csv";
  CHECK(run_cps(traced, dir).err.find("trace: ") != std::string::npos);
  CHECK(run_cps(traced + " --quiet", dir).err.empty());
  fs::remove_all(dir);
}
