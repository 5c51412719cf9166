// `cps export SCENE --fclib FILE.hdf5 --at STEP` as a user runs it: the file read back with
// FCLIB's own reader (fclib_read_local) and checked against the system the engine solved at that
// step, captured in-process through World::set_solve_observer (cps/step_system.h): W against
// A = J M^-1 J^T (Eq. 6.2.9) on each contact's (normal, tangent, tangent) rows, q against
// -dt b, mu against the friction rows' coefficient; then the mapping itself: u = W r + q with
// r = dt lambda gives dt (A lambda - b), and the exact solution (demos/analysis/exact_lcp.h)
// satisfies the FCLIB problem's normal complementarity and sticking. Bad input: exit 2, nothing
// written.
#include "cli_support.h"

#include "exact_lcp.h"
#include "scene.h"

#include <catch2/catch.hpp>

// fclib.h declares C functions without extern "C".
extern "C" {
#include <fclib.h>
}

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cli_test::run_cps;

namespace {

using namespace cps;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Steps at rest (as tests/physics/test_exact_reference.cpp): the stack from about 1.5 s, the
// funnel's pile by 10 s.
constexpr std::int64_t kStackStep = 300;   // 5 s at 1/60 s
constexpr std::int64_t kFunnelStep = 600;  // 10 s

// The first solve of step `step` of `scene` with the scene's own parameters, as cps runs it.
StepSystem capture(const char* scene, std::int64_t step) {
  scenes::Run run = scenes::make_run(*scenes::find_scene(scene));
  std::optional<StepSystem> captured;
  run.world.set_solve_observer([&](const StepSystem& s) {
    if (s.step == step && s.solve == 0) captured = s;
  });
  while (!captured && run.world.counters().steps <= step) run.step();
  REQUIRE(captured);
  return *captured;
}

// An FCLIB local problem read back, freed with fclib's own delete.
struct Local {
  fclib_local* p = nullptr;
  explicit Local(const fs::path& path) : p(fclib_read_local(path.c_str())) {}
  ~Local() {
    if (p != nullptr) {
      fclib_delete_local(p);
      std::free(p);
    }
  }
  Local(const Local&) = delete;
  Local& operator=(const Local&) = delete;
};

// An fclib matrix (compressed columns, triplets or compressed rows) as a dense matrix.
Eigen::MatrixXd dense(const fclib_matrix& m) {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(m.m, m.n);
  if (m.nz == -1) {
    for (int col = 0; col < m.n; ++col) {
      for (int k = m.p[col]; k < m.p[col + 1]; ++k) d(m.i[k], col) += m.x[k];
    }
  } else if (m.nz == -2) {
    for (int row = 0; row < m.m; ++row) {
      for (int k = m.p[row]; k < m.p[row + 1]; ++k) d(row, m.i[k]) += m.x[k];
    }
  } else {
    for (int k = 0; k < m.nz; ++k) d(m.p[k], m.i[k]) += m.x[k];
  }
  return d;
}

// The rows of s the file should hold, in its order: per contact row (in cps's order) the
// contact row, then its friction rows in cps's order. Built here from the kinds and normal_row
// alone, apart from the exporter's code.
std::vector<int> expected_rows(const StepSystem& s) {
  std::vector<int> rows;
  for (Eigen::Index j = 0; j < s.rows(); ++j) {
    if (s.kinds[static_cast<std::size_t>(j)] != RowKind::contact) continue;
    rows.push_back(static_cast<int>(j));
    for (Eigen::Index t = 0; t < s.rows(); ++t) {
      if (s.kinds[static_cast<std::size_t>(t)] == RowKind::friction &&
          s.normal_row[static_cast<std::size_t>(t)] == j) {
        rows.push_back(static_cast<int>(t));
      }
    }
  }
  return rows;
}

// The problem's force scale (N), as in test_exact_reference.cpp: the largest |lambda_j| and
// |b_j| / A_jj over the rows that touch a movable body.
double force_scale(const StepSystem& s, const Eigen::VectorXd& lambda) {
  double scale = 0.0;
  for (Eigen::Index j = 0; j < s.rows(); ++j) {
    const double d = s.A.coeff(j, j);
    if (d > 0.0) scale = std::max({scale, std::abs(lambda[j]), std::abs(s.b[j]) / d});
  }
  return scale;
}

void check_export(const char* scene, double seconds, std::int64_t step) {
  const fs::path dir = cli_test::fresh_dir(std::string("cps-test-fclib-") + scene);
  const std::string file = std::string(scene) + ".hdf5";
  const cli_test::Result r = run_cps("export " + std::string(scene) + " --seconds " +
                                         std::to_string(seconds) + " --at " + std::to_string(step) +
                                         " --fclib out/" + file,
                                     dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  // Only the file, its rows and run.json: the temporaries were renamed.
  std::vector<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "out")) {
    names.push_back(e.path().filename().string());
  }
  std::vector<std::string> expected = {file, fs::path(file).stem().string() + "-rows.csv", "run.json"};
  std::sort(names.begin(), names.end());
  std::sort(expected.begin(), expected.end());
  CHECK(names == expected);

  const StepSystem s = capture(scene, step);
  const std::vector<int> rows = expected_rows(s);
  const Eigen::MatrixXd A(s.A);
  Local local(dir / "out" / file);
  REQUIRE(local.p != nullptr);
  const fclib_local& p = *local.p;
  const int m = static_cast<int>(rows.size());
  const int contacts = m / 3;
  // Every row is a contact's (no rods in these scenes), three to a contact.
  CHECK(m == s.rows());
  CHECK(m % 3 == 0);
  REQUIRE(p.spacedim == 3);
  REQUIRE(p.W->m == m);
  REQUIRE(p.W->n == m);
  CHECK(p.V == nullptr);
  CHECK(p.R == nullptr);
  REQUIRE(p.info != nullptr);
  REQUIRE(p.info->title != nullptr);
  CHECK(std::string(p.info->title) == "cps " + std::string(scene) + " step " + std::to_string(step));
  REQUIRE(p.info->description != nullptr);
  CHECK(std::string(p.info->description).find("dt = ") != std::string::npos);
  REQUIRE(p.info->math_info != nullptr);
  CHECK(std::string(p.info->math_info).find("q = -dt b") != std::string::npos);

  // W = A on the rows (copied: round-off of one conversion at most), q = -dt b (one product:
  // half an ulp), mu = the friction rows' coefficient (copied).
  const Eigen::MatrixXd W = dense(*p.W);
  double w_diff = 0.0;
  double q_diff = 0.0;
  double mu_diff = 0.0;
  double b_max = 0.0;
  for (int i = 0; i < m; ++i) {
    for (int k = 0; k < m; ++k) w_diff = std::max(w_diff, std::abs(W(i, k) - A(rows[i], rows[k])));
    q_diff = std::max(q_diff, std::abs(p.q[i] - (-s.dt * s.b[rows[i]])));
    b_max = std::max(b_max, std::abs(s.b[rows[i]]));
  }
  for (int c = 0; c < contacts; ++c) {
    mu_diff = std::max(mu_diff, std::abs(p.mu[c] - s.mu[rows[3 * c + 1]]));
    CHECK(s.mu[rows[3 * c + 1]] == s.mu[rows[3 * c + 2]]);
  }
  const double a_max = A.cwiseAbs().maxCoeff();
  CHECK(w_diff <= kEps * a_max);
  CHECK(q_diff <= kEps * s.dt * b_max);
  CHECK(mu_diff == 0.0);

  // The mapping: with r = dt lambda, u = W r + q is dt (A lambda - b) on the rows, for the
  // engine's lambda and for the exact one. Round-off: one product per entry of a row of A times
  // lambda (m terms) and the sum with -dt b: m + 2 ulps of dt (|A| |lambda| + |b|).
  const analysis::ExactSolution exact = analysis::solve_exact(s);
  double u_diff = 0.0;
  double u_tol = 0.0;
  Eigen::VectorXd u_exact(m);
  Eigen::VectorXd r_exact(m);
  for (const Eigen::VectorXd* lambda : {&s.lambda, &exact.lambda}) {
    Eigen::VectorXd r_vec(m);
    for (int i = 0; i < m; ++i) r_vec[i] = s.dt * (*lambda)[rows[i]];
    const Eigen::VectorXd u = W * r_vec + Eigen::Map<const Eigen::VectorXd>(p.q, m);
    const Eigen::VectorXd w = A * *lambda - s.b;
    const Eigen::VectorXd scale = A.cwiseAbs() * lambda->cwiseAbs() + s.b.cwiseAbs();
    for (int i = 0; i < m; ++i) {
      u_diff = std::max(u_diff, std::abs(u[i] - s.dt * w[rows[i]]));
      u_tol = std::max(u_tol, (m + 2) * kEps * s.dt * scale[rows[i]]);
    }
    u_exact = u;
    r_exact = r_vec;
  }
  CHECK(u_diff <= u_tol);

  // The exact solution of cps's box problem in FCLIB's terms: every contact's Signorini
  // condition (r_N >= 0, u_N >= 0, r_N u_N = 0), and u_T = 0 where both friction rows are
  // strictly inside their box (sticking). Tolerances as test_exact_reference.cpp's: 1e-11 of the
  // force scale, times dt for impulses, times dt max A_jj for velocities. A wrong mapping
  // (W = dt A, q = +dt b, another row order) breaks these.
  const double force_tol = 1e-11 * force_scale(s, exact.lambda);
  const double r_tol = s.dt * force_tol;                            // N s
  const double v_tol = s.dt * A.diagonal().maxCoeff() * force_tol;  // m/s
  double worst_signorini = 0.0;
  double worst_stick = 0.0;
  int sticking = 0;
  for (int c = 0; c < contacts; ++c) {
    const double rn = r_exact[3 * c];
    const double un = u_exact[3 * c];
    CHECK(rn >= -r_tol);
    CHECK(un >= -v_tol);
    worst_signorini = std::max(worst_signorini, std::abs(rn * un));
    bool inside = true;
    for (int k = 1; k <= 2; ++k) {
      const int j = rows[3 * c + k];
      const double l = exact.lambda[j];
      inside = inside && l > s.c_min[j] + 1e-6 * (s.c_max[j] - s.c_min[j]) &&
               l < s.c_max[j] - 1e-6 * (s.c_max[j] - s.c_min[j]);
    }
    if (inside) {
      ++sticking;
      worst_stick = std::max({worst_stick, std::abs(u_exact[3 * c + 1]), std::abs(u_exact[3 * c + 2])});
    }
  }
  // r_N u_N: at most the impulse scale times the velocity tolerance, and vice versa.
  CHECK(worst_signorini <= 2.0 * s.dt * force_scale(s, exact.lambda) * v_tol);
  CHECK(worst_stick <= v_tol);
  // Not vacuous: the pile pushes.
  CHECK(r_exact.maxCoeff() > 10.0 * r_tol);
  std::printf("fclib %s step %lld: %d contacts, W %d x %d (%d stored), |W - A| %.3g (tol %.3g), "
              "|q + dt b| %.3g (tol %.3g), mu %.3g, |u - dt w| %.3g (tol %.3g), "
              "max |r_N u_N| %.3g N m, sticking contacts %d with max |u_T| %.3g m/s (tol %.3g)\n",
              scene, static_cast<long long>(step), contacts, p.W->m, p.W->n, p.W->nzmax, w_diff,
              kEps * a_max, q_diff, kEps * s.dt * b_max, mu_diff, u_diff, u_tol, worst_signorini,
              sticking, worst_stick, v_tol);
  fs::remove_all(dir);
}

}  // namespace

TEST_CASE("export --fclib writes the resting stack's and funnel's solves as FCLIB problems that "
          "read back as the engine's A, b and mu", "[fclib]") {
  SECTION("stack") { check_export("stack", 6.0, kStackStep); }
  SECTION("funnel") { check_export("funnel", 11.0, kFunnelStep); }
}

TEST_CASE("export --fclib writes the pendulum grid's rods as the bilateral rows V, R, s",
          "[fclib]") {
  // Step 10 (1/6 s): the balls touch their neighbours, each hangs from its rod.
  const std::int64_t step = 10;
  const fs::path dir = cli_test::fresh_dir("cps-test-fclib-rods");
  const cli_test::Result r =
      run_cps("export pendulum_grid --seconds 0.2 --at " + std::to_string(step) + " --fclib out/p.hdf5", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const StepSystem s = capture("pendulum_grid", step);
  const std::vector<int> rows = expected_rows(s);
  std::vector<int> rods;
  for (Eigen::Index j = 0; j < s.rows(); ++j) {
    if (s.kinds[static_cast<std::size_t>(j)] == RowKind::distance) rods.push_back(static_cast<int>(j));
  }
  REQUIRE(!rods.empty());
  REQUIRE(rows.size() % 3 == 0);
  Local local(dir / "out" / "p.hdf5");
  REQUIRE(local.p != nullptr);
  const fclib_local& p = *local.p;
  const int m = static_cast<int>(rows.size());
  const int d = static_cast<int>(rods.size());
  REQUIRE(p.W->m == m);
  REQUIRE(p.V != nullptr);
  REQUIRE(p.R != nullptr);
  REQUIRE(p.V->m == m);
  REQUIRE(p.V->n == d);
  REQUIRE(p.R->m == d);
  REQUIRE(p.R->n == d);
  const Eigen::MatrixXd A(s.A);
  const Eigen::MatrixXd V = dense(*p.V);
  const Eigen::MatrixXd R = dense(*p.R);
  double v_diff = 0.0;
  double r_diff = 0.0;
  double s_diff = 0.0;
  double b_max = 0.0;
  for (int k = 0; k < d; ++k) {
    for (int i = 0; i < m; ++i) v_diff = std::max(v_diff, std::abs(V(i, k) - A(rows[i], rods[k])));
    for (int i = 0; i < d; ++i) r_diff = std::max(r_diff, std::abs(R(i, k) - A(rods[i], rods[k])));
    s_diff = std::max(s_diff, std::abs(p.s[k] - (-s.dt * s.b[rods[k]])));
    b_max = std::max(b_max, std::abs(s.b[rods[k]]));
  }
  const double a_max = A.cwiseAbs().maxCoeff();
  CHECK(v_diff <= kEps * a_max);
  CHECK(r_diff <= kEps * a_max);
  CHECK(s_diff <= kEps * s.dt * b_max);
  // The rods' equation V^T r + R l + s = 0 is dt (A lambda - b) on the rods' rows = dt w_D: for
  // the exact solution 0 to its round-off (1e-11 of the force scale, times dt max A_jj).
  const analysis::ExactSolution exact = analysis::solve_exact(s);
  Eigen::VectorXd rc(m);
  Eigen::VectorXd l(d);
  for (int i = 0; i < m; ++i) rc[i] = s.dt * exact.lambda[rows[i]];
  for (int k = 0; k < d; ++k) l[k] = s.dt * exact.lambda[rods[k]];
  const Eigen::VectorXd rod_velocity = V.transpose() * rc + R * l + Eigen::Map<const Eigen::VectorXd>(p.s, d);
  const double v_tol = s.dt * A.diagonal().maxCoeff() * 1e-11 * force_scale(s, exact.lambda);
  CHECK(rod_velocity.cwiseAbs().maxCoeff() <= v_tol);
  std::printf("fclib pendulum_grid step %lld: %d contacts, %d rods, |V - A_CD| %.3g, |R - A_DD| "
              "%.3g, |s + dt b_D| %.3g, max |V^T r + R l + s| %.3g m/s (tol %.3g)\n",
              static_cast<long long>(step), m / 3, d, v_diff, r_diff, s_diff,
              rod_velocity.cwiseAbs().maxCoeff(), v_tol);
  fs::remove_all(dir);
}

TEST_CASE("export --fclib writes each row's bounds and lambda beside the file, from which cps's "
          "box problem is solved again", "[fclib]") {
  const fs::path dir = cli_test::fresh_dir("cps-test-fclib-rows");
  const cli_test::Result r = run_cps("export stack --seconds 6 --at 300 --fclib out/s.hdf5", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const StepSystem s = capture("stack", kStackStep);
  // The rows file: a header and one line per cps row.
  std::FILE* f = std::fopen((dir / "out" / "s-rows.csv").c_str(), "r");
  REQUIRE(f != nullptr);
  std::vector<std::vector<std::string>> table;
  char buffer[1024];
  while (std::fgets(buffer, sizeof buffer, f) != nullptr) {
    std::vector<std::string> cells(1);
    for (const char* c = buffer; *c != '\0' && *c != '\n'; ++c) {
      if (*c == ',') cells.emplace_back(); else cells.back() += *c;
    }
    table.push_back(cells);
  }
  std::fclose(f);
  REQUIRE(table.size() == static_cast<std::size_t>(s.rows()) + 1);
  REQUIRE(table[0].size() == 11);
  CHECK(table[0][2] == "fclib");
  CHECK(table[0][10] == "lambda_exact_N");
  // From the FCLIB file's W and q and the rows' bounds: the natural map of the box problem at
  // the exact lambda of the rows file is 0 to the exact solve's tolerances (1e-9 of the force
  // scale for its residual, and as much for the least-norm member's bounds); and the engine's
  // lambda is the captured one, to the digit.
  Local local(dir / "out" / "s.hdf5");
  REQUIRE(local.p != nullptr);
  const Eigen::MatrixXd W = dense(*local.p->W);
  const int m = local.p->W->m;
  Eigen::VectorXd r_local = Eigen::VectorXd::Zero(m);
  std::vector<int> cps_row(static_cast<std::size_t>(m), -1);
  double scale = 0.0;
  for (std::size_t k = 1; k < table.size(); ++k) {
    const std::vector<std::string>& row = table[k];
    REQUIRE(row.size() == 11);
    const int j = std::stoi(row[0]);
    CHECK(std::stod(row[9]) == s.lambda[j]);
    CHECK(std::stod(row[3]) == s.c_min[j]);
    scale = std::max(scale, std::abs(std::stod(row[10])));
    if (row[2].rfind("r[", 0) == 0) {
      const int i = std::stoi(row[2].substr(2));
      REQUIRE(i < m);
      cps_row[static_cast<std::size_t>(i)] = j;
      r_local[i] = s.dt * std::stod(row[10]);
    }
  }
  REQUIRE(std::count(cps_row.begin(), cps_row.end(), -1) == 0);
  const Eigen::VectorXd u = W * r_local + Eigen::Map<const Eigen::VectorXd>(local.p->q, m);
  double residual = 0.0;
  for (int i = 0; i < m; ++i) {
    const std::vector<std::string>& row = table[static_cast<std::size_t>(cps_row[static_cast<std::size_t>(i)]) + 1];
    const double lambda = r_local[i] / s.dt;
    const double w = u[i] / s.dt;
    const double fixed = std::clamp(lambda - w / W(i, i), std::stod(row[3]), std::stod(row[4]));
    residual = std::max(residual, std::abs(lambda - fixed));
  }
  CHECK(residual <= 2e-9 * scale);
  CHECK(scale > 1.0);  // not vacuous: the stack pushes
  fs::remove_all(dir);
}

TEST_CASE("export --fclib with several steps writes one file per step", "[fclib]") {
  const fs::path dir = cli_test::fresh_dir("cps-test-fclib-steps");
  const cli_test::Result r = run_cps("export intersecting_stack --seconds 0.1 --at 5,1 --fclib out/is.hdf5", dir);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  for (const int step : {1, 5}) {
    const fs::path file = dir / "out" / ("is-step" + std::to_string(step) + ".hdf5");
    Local local(file);
    REQUIRE(local.p != nullptr);
    CHECK(std::string(local.p->info->title) == "cps intersecting_stack step " + std::to_string(step));
    const StepSystem s = capture("intersecting_stack", step);
    CHECK(local.p->W->m == static_cast<int>(expected_rows(s).size()));
  }
  CHECK(fs::exists(dir / "out" / "is-step1-rows.csv"));
  CHECK(fs::exists(dir / "out" / "is-step5-rows.csv"));
  CHECK_FALSE(fs::exists(dir / "out" / "is.hdf5"));
  fs::remove_all(dir);
}

TEST_CASE("export --fclib refuses bad input with exit 2 and writes nothing", "[fclib]") {
  const fs::path dir = cli_test::fresh_dir("cps-test-fclib-bad");
  const std::string base = "export stack --seconds 0.1 ";
  struct Case {
    std::string args;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {"--at 6 --fclib out/s.hdf5", "'6' is not a step of this run"},       // 6 steps: 0 .. 5
      {"--at 99999999999 --fclib out/s.hdf5", "[0, 5]"},
      {"--at '' --fclib out/s.hdf5", "--at"},                                 // empty list
      {"--at 1,,2 --fclib out/s.hdf5", "''"},
      {"--at x --fclib out/s.hdf5", "'x' is not a step"},
      {"--at 1.5 --fclib out/s.hdf5", "'1.5'"},
      {"--at -1 --fclib out/s.hdf5", "--at"},
      {"--at 1", "--fclib"},                                                   // --at alone
      {"--fclib out/s.h5", "ending in .hdf5"},
      {"--fclib out/s.hdf5 --out out/s.glb", "--out"},
      {"--fclib out/s.hdf5 --fps 10", "--fps"},
      {"", "--fclib"},                                                          // neither
      {"--fclib foreign.hdf5", "foreign.hdf5"},                                 // not cps's
  };
  {
    std::FILE* f = std::fopen((dir / "foreign.hdf5").c_str(), "w");
    REQUIRE(f != nullptr);
    std::fputs("not written by cps\n", f);
    std::fclose(f);
  }
  for (const Case& c : cases) {
    const cli_test::Result r = run_cps(base + c.args, dir);
    INFO(c.args << "\n" << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c.needle) != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "out"));
    CHECK(cli_test::slurp(dir / "foreign.hdf5") == "not written by cps\n");
  }
  // With --force the foreign file is replaced by an FCLIB file (intersecting_stack: contacts
  // from the first step).
  const cli_test::Result forced =
      run_cps("export intersecting_stack --seconds 0.1 --fclib foreign.hdf5 --force", dir);
  INFO(forced.err);
  CHECK(forced.exit_code == 0);
  Local local(dir / "foreign.hdf5");
  CHECK(local.p != nullptr);
  fs::remove_all(dir);
}

TEST_CASE("export --fclib without FCLIB's library fails naming it, and writes nothing", "[fclib]") {
  // cps opens libfclib only for --fclib (dlopen); CPS_FCLIB_LIBRARY names one that is not there.
  const fs::path dir = cli_test::fresh_dir("cps-test-fclib-nolib");
  const std::string missing = "libcps-test-no-such-fclib.so.0";
  const cli_test::Result r = run_cps("export stack --seconds 0.1 --at 1 --fclib out/s.hdf5", dir,
                                     "CPS_FCLIB_LIBRARY=" + missing);
  INFO(r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.err.find(missing) != std::string::npos);
  CHECK(r.err.find("libfclib0") != std::string::npos);
  CHECK(r.err.find("nothing written") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "out"));
  // Everything else works without it.
  const cli_test::Result list = run_cps("list", dir, "CPS_FCLIB_LIBRARY=" + missing);
  CHECK(list.exit_code == 0);
  CHECK(list.out.find("stack") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("export --fclib of a push that solves no A lambda = b says so, and writes nothing",
          "[fclib]") {
  // The soft step, xpbd and avbd sweep their own rows: the intersecting stack has contacts from
  // its first step, and still no solve to write.
  const fs::path dir = cli_test::fresh_dir("cps-test-fclib-own-sweeps");
  for (const char* push : {"soft", "xpbd", "avbd"}) {
    const cli_test::Result r = run_cps(std::string("export intersecting_stack --seconds 0.1 --at 2 --push ") +
                                           push + " --fclib out/s.hdf5",
                                       dir);
    INFO(push << "\n" << r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.find(std::string("push ") + push + " sweeps its own rows") != std::string::npos);
    CHECK(r.err.find("nothing written") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "out"));
  }
  fs::remove_all(dir);
}
