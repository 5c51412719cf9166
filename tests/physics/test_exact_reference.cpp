// The exact reference of a step (demos/analysis/exact_lcp.h) on the paper's stack (Sec. 10.1)
// and funnel (Sec. 10.3) at rest: a step's system captured through World::set_solve_observer
// (cps/step_system.h), solved exactly with Siconos' Lemke method, judged by the per-step criteria
// (demos/analysis/criteria.h), and the engine's own PGS and Jacobi sweeps (Sec. 7) measured
// against it as their number grows.
#include "capture.h"
#include "criteria.h"
#include "exact_lcp.h"
#include "scene.h"
#include "state_hash.h"
#include "stress/mass_ratio.h"
#include "stress/stress.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cfenv>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <limits>
#include <vector>
#include <string>

namespace {

using namespace cps;

// Steps at rest: the stack's fifth cube lands at about 0.8 s and the column is still from
// about 1.5 s (stack.cpp); the funnel's pile rests by 10 s (funnel.cpp).
constexpr std::int64_t kStackStep = 300;   // 5 s
constexpr std::int64_t kFunnelStep = 600;  // 10 s

// The first solve of step `step` of `scene` (the scene's own parameters, with `friction` and
// `assembly`), captured by the world's solve observer.
StepSystem capture(const char* scene, std::int64_t step,
                   FrictionModel friction = FrictionModel::fixed,
                   Assembly assembly = Assembly::matrix_free) {
  scenes::Overrides o;
  o.set("friction_model", friction);
  o.set("assembly", assembly);
  return test::capture(scene, step, o);
}

// The problem's force scale (N): the largest |lambda*_j| and |b_j| / A_jj over the rows that
// touch a movable body. Round-off in lambda is a few ulps of it.
double force_scale(const StepSystem& s, const Eigen::VectorXd& lambda) {
  double scale = 0.0;
  for (Eigen::Index j = 0; j < s.rows(); ++j) {
    const double d = s.A.coeff(j, j);
    if (d > 0.0) scale = std::max({scale, std::abs(lambda[j]), std::abs(s.b[j]) / d});
  }
  return scale;
}

// The largest A_jj (1/kg): a force error e gives at most about max A_jj e of w (m/s^2) per row.
double largest_diagonal(const StepSystem& s) {
  double d = 0.0;
  for (Eigen::Index j = 0; j < s.rows(); ++j) d = std::max(d, s.A.coeff(j, j));
  return d;
}

void check_exact(const StepSystem& s) {
  const analysis::ExactSolution exact = analysis::solve_exact(s);
  const analysis::Criteria c = analysis::evaluate(s, exact, exact.lambda);
  // Round-off: 1e-11 of the force scale (double precision leaves 1e-16 per operation; Lemke's
  // pivots and the polish's pseudo-inverse of A_FF, condition about 1e3 here, a few hundred more).
  const double force_tol = 1e-11 * force_scale(s, exact.lambda);
  const double velocity_tol = s.dt * largest_diagonal(s) * force_tol;  // m/s
  INFO("rows " << s.rows() << ", force scale " << force_scale(s, exact.lambda) << " N, "
               << exact.method);
  CHECK(c.natural_map_N <= force_tol);
  CHECK(c.signorini_force_N <= force_tol);
  CHECK(c.signorini_velocity_mps <= velocity_tol);
  // lambda_j dt w_j: at most the force scale times the velocity tolerance, and vice versa.
  CHECK(c.complementarity_W <= 2.0 * force_scale(s, exact.lambda) * velocity_tol);
  CHECK(c.friction_violation_N <= force_tol);
  CHECK(c.velocity_error_mps == 0.0);
  CHECK(c.lambda_error_N == 0.0);
  // A solution's distance to the solutions is 0, with either friction model.
  CHECK(c.lambda_error_exact);
  CHECK(!c.diverged);
  // Not trivially so: the solution pushes.
  CHECK(exact.lambda.maxCoeff() > 1.0);
}

}  // namespace

TEST_CASE("a captured step is the system the engine solved, and observing it changes nothing",
          "[exact]") {
  for (const Assembly assembly : {Assembly::matrix_free, Assembly::explicit_matrices}) {
    const StepSystem s = capture("stack", kStackStep, FrictionModel::fixed, assembly);
    INFO("assembly " << (assembly == Assembly::matrix_free ? "matrix-free" : "explicit"));
    REQUIRE(s.rows() > 0);
    REQUIRE(s.kinds.size() == static_cast<std::size_t>(s.rows()));
    // A = J M^-1 J^T is symmetric.
    const Eigen::MatrixXd A(s.A);
    CHECK((A - A.transpose()).cwiseAbs().maxCoeff() <= 1e-14 * A.cwiseAbs().maxCoeff());
    // The engine's sweeps on the captured system give back the engine's lambda: the explicit
    // path's solve_lcp runs the same code; the matrix-free path agrees with it to round-off.
    const Eigen::VectorXd again = solve_sweeps(s, s.solver, s.iterations, &s.initial);
    CHECK((again - s.lambda).cwiseAbs().maxCoeff() <= 1e-9 * s.lambda.cwiseAbs().maxCoeff());
  }
  // The same run with and without an observer ends in the same state.
  scenes::Run plain = scenes::make_run(*scenes::find_scene("stack"));
  scenes::Run observed = scenes::make_run(*scenes::find_scene("stack"));
  int solves = 0;
  observed.world.set_solve_observer([&](const StepSystem&) { ++solves; });
  for (int k = 0; k < 120; ++k) {
    plain.step();
    observed.step();
  }
  // One solve a step with the paper's push factor, once the cubes touch.
  CHECK(solves > 0);
  CHECK(solves == observed.world.counters().solves);
  CHECK(scenes::state_hash(plain.world) == scenes::state_hash(observed.world));
  // A filter asked before each solve is written out: told the step, the solve and the rows the
  // observer then sees, and a false keeps the observer from it.
  scenes::Run filtered = scenes::make_run(*scenes::find_scene("stack"));
  int asked = 0;
  std::vector<std::int64_t> seen;
  Eigen::Index asked_rows = -1;
  filtered.world.set_solve_observer(
      [&](const StepSystem& s) {
        seen.push_back(s.step);
        CHECK(s.rows() == asked_rows);
      },
      [&](std::int64_t step, int solve, Eigen::Index rows) {
        ++asked;
        CHECK(solve == 0);
        CHECK(step == static_cast<std::int64_t>(filtered.world.counters().steps));
        asked_rows = rows;
        return step % 10 == 0;
      });
  for (int k = 0; k < 120; ++k) filtered.step();
  CHECK(asked == solves);
  REQUIRE_FALSE(seen.empty());
  CHECK(std::all_of(seen.begin(), seen.end(), [](std::int64_t step) { return step % 10 == 0; }));
  CHECK(seen.size() < static_cast<std::size_t>(asked));
  CHECK(scenes::state_hash(filtered.world) == scenes::state_hash(plain.world));
}

TEST_CASE("the exact solution of the resting stack and funnel satisfies every criterion to "
          "round-off", "[exact]") {
  SECTION("stack") { check_exact(capture("stack", kStackStep)); }
  SECTION("funnel") { check_exact(capture("funnel", kFunnelStep)); }
  SECTION("stack, coupled friction") {
    check_exact(capture("stack", kStackStep, FrictionModel::coupled));
  }
}

TEST_CASE("on the resting funnel PGS converges to the exact solution and Jacobi does not",
          "[exact]") {
  const StepSystem s = capture("funnel", kFunnelStep);
  const analysis::ExactSolution exact = analysis::solve_exact(s);
  // The pile's A is non-singular on the rows that push: the solution is unique.
  CHECK(exact.null_basis.cols() == 0);
  const auto error = [&](SolverKind method, int sweeps) {
    return analysis::evaluate(s, exact, solve_sweeps(s, method, sweeps));
  };
  // Measured: relative error 0.22 at 1000 sweeps, 0.018 at 10^4, 6e-15 at 10^5.
  const analysis::Criteria pgs_1000 = error(SolverKind::pgs, 1000);
  const analysis::Criteria pgs_10000 = error(SolverKind::pgs, 10000);
  const analysis::Criteria pgs_100000 = error(SolverKind::pgs, 100000);
  CHECK(pgs_1000.lambda_error_relative > 1e-2);
  CHECK(pgs_10000.lambda_error_relative < pgs_1000.lambda_error_relative);
  CHECK(pgs_100000.lambda_error_relative <= 1e-8);
  CHECK(pgs_100000.velocity_error_mps <= 1e-8 * s.dt * largest_diagonal(s) * exact.lambda.norm());
  CHECK(pgs_100000.natural_map_N <= 1e-8 * force_scale(s, exact.lambda));
  // Jacobi settles into a cycle far from the solution (measured: natural-map residual 194 N
  // from 1000 sweeps on).
  CHECK(error(SolverKind::jacobi, 10000).natural_map_N > 1.0);
}

TEST_CASE("on the resting stack PGS's velocities converge but its forces stay far from every "
          "exact solution, and Jacobi diverges", "[exact]") {
  const StepSystem s = capture("stack", kStackStep);
  const analysis::ExactSolution exact = analysis::solve_exact(s);
  // Four contact points a face: A is singular and the exact solutions form a set.
  CHECK(exact.null_basis.cols() > 0);
  const Eigen::VectorXd y = solve_sweeps(s, SolverKind::pgs, 10000);
  const analysis::Criteria pgs = analysis::evaluate(s, exact, y);
  // Measured at 10^4 sweeps: velocity error 5.5e-7 m/s, natural-map residual 3e-6 N, and 11.4 N
  // (0.19 of |lambda*|) from the set of exact solutions.
  CHECK(pgs.velocity_error_mps <= 1e-5);
  CHECK(pgs.natural_map_N <= 1e-4);
  CHECK(pgs.lambda_error_relative > 0.05);
  // Jacobi grows without bound (measured: 2e23 N residual at 100 sweeps).
  const Eigen::VectorXd jacobi = solve_sweeps(s, SolverKind::jacobi, 100);
  const double r = natural_map_residual(s, jacobi).maxCoeff();
  CHECK((!std::isfinite(r) || r > 1e3 * force_scale(s, exact.lambda)));
}

namespace {

// Whether x is an exact solution of s: within the bounds and with a natural-map residual at
// round-off of the force scale (N).
bool is_solution(const StepSystem& s, const Eigen::VectorXd& x, double force_scale_N) {
  const double tol = 1e-8 * force_scale_N;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    if (x[j] < s.c_min[j] - tol || x[j] > s.c_max[j] + tol) return false;
  }
  return natural_map_residual(s, x).maxCoeff() <= tol;
}

// Two contact rows on the same body along the same normal (A = [[1, 1], [1, 1]] 1/kg, b = 2 for
// each): the exact solutions are the segment lambda_1 + lambda_2 = 2 N, lambda >= 0, from
// (2, 0) to (0, 2), whichever end Lemke returns.
StepSystem twin_contacts() {
  StepSystem s;
  s.dt = 1.0 / 60.0;
  Eigen::SparseMatrix<double, Eigen::RowMajor> A(2, 2);
  A.insert(0, 0) = 1.0;
  A.insert(0, 1) = 1.0;
  A.insert(1, 0) = 1.0;
  A.insert(1, 1) = 1.0;
  s.A = A;
  s.b = Eigen::Vector2d(2.0, 2.0);
  s.c_min = Eigen::Vector2d::Zero();
  s.c_max = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  s.mu = Eigen::Vector2d::Zero();
  s.normal_row = {-1, -1};
  s.kinds = {RowKind::contact, RowKind::contact};
  s.initial = Eigen::Vector2d::Zero();
  s.lambda = Eigen::Vector2d::Zero();
  return s;
}

}  // namespace

TEST_CASE("the force error is the distance to the whole set of exact solutions, not to the "
          "face of the one found", "[exact]") {
  const StepSystem s = twin_contacts();
  const analysis::ExactSolution exact = analysis::solve_exact(s);
  REQUIRE(is_solution(s, exact.lambda, 2.0));
  // The least-norm solution is (1, 1): |lambda*| = sqrt(2) N.
  CHECK(std::abs(exact.smallest_norm_N - std::sqrt(2.0)) <= 1e-12);
  struct Case {
    Eigen::Vector2d y;        // N
    Eigen::Vector2d nearest;  // N: the projection onto the segment, by hand
  };
  const Case cases[] = {
      {{3.0, 3.0}, {1.0, 1.0}},    // onto the line, inside the segment
      {{-1.0, 1.0}, {0.0, 2.0}},   // onto the line at an end
      {{-2.0, 1.0}, {0.0, 2.0}},   // the line's projection (-0.5, 2.5) leaves the bounds
      {{5.0, -4.0}, {2.0, 0.0}},   // the other end
      {{1.5, 0.5}, {1.5, 0.5}},    // a member
  };
  for (const Case& c : cases) {
    INFO("y = (" << c.y.transpose() << ")");
    const analysis::ExactSolution::Distance d = exact.distance(s, c.y);
    CHECK(d.exact);
    CHECK((d.nearest - c.nearest).norm() <= 1e-9);
    CHECK(std::abs(d.upper_N - (c.y - c.nearest).norm()) <= 1e-9);
    CHECK(d.lower_N <= d.upper_N);
    CHECK(d.lower_N >= d.upper_N - 1e-6 * 2.0);
    const analysis::Criteria k = analysis::evaluate(s, exact, c.y);
    CHECK(std::abs(k.lambda_error_relative - k.lambda_error_N / std::sqrt(2.0)) <= 1e-12);
  }
}

TEST_CASE("on the resting stack the force error is certified as the distance to the solution "
          "set, and relative errors are over |lambda*|", "[exact]") {
  const StepSystem s = capture("stack", kStackStep);
  const analysis::ExactSolution exact = analysis::solve_exact(s);
  REQUIRE(exact.null_basis.cols() > 0);
  REQUIRE(is_solution(s, exact.lambda, exact.force_scale_N));
  // Members of the set: Lemke's, the least-norm one, and the nearest to several PGS iterates.
  std::vector<Eigen::VectorXd> members{exact.lambda,
                                       exact.distance(s, Eigen::VectorXd::Zero(s.rows())).nearest};
  CHECK(std::abs(members[1].norm() - exact.smallest_norm_N) <= 1e-9 * exact.force_scale_N);
  CHECK(exact.smallest_norm_N <= exact.lambda.norm());
  for (const int sweeps : {25, 1000, 10000}) {
    INFO(sweeps << " PGS sweeps");
    const Eigen::VectorXd y = solve_sweeps(s, SolverKind::pgs, sweeps);
    const analysis::ExactSolution::Distance d = exact.distance(s, y);
    // Certified: the dual bound meets the distance to a member.
    CHECK(d.exact);
    CHECK(d.upper_N - d.lower_N <= 1e-6 * exact.force_scale_N);
    CHECK(is_solution(s, d.nearest, exact.force_scale_N));
    CHECK(std::abs((y - d.nearest).norm() - d.upper_N) <= 1e-12 * exact.force_scale_N);
    // The projection onto a convex set: (y - p) . (m - p) <= 0 for every member m (to round-off).
    for (const Eigen::VectorXd& m : members) {
      CHECK((y - d.nearest).dot(m - d.nearest) <= 1e-8 * exact.force_scale_N * exact.force_scale_N);
      CHECK(d.upper_N <= (y - m).norm() + 1e-9 * exact.force_scale_N);
    }
    members.push_back(d.nearest);
  }
  // Jacobi's error over |lambda*| (measured: 2.3e5 N at 25 sweeps, 3800 |lambda*|), and a
  // diverged Jacobi (1000 sweeps) reported as such, never as NaN.
  const analysis::Criteria jacobi_25 = analysis::evaluate(s, exact, solve_sweeps(s, SolverKind::jacobi, 25));
  CHECK(jacobi_25.lambda_error_relative == jacobi_25.lambda_error_N / exact.smallest_norm_N);
  CHECK(jacobi_25.lambda_error_relative > 100.0);
  CHECK(!jacobi_25.diverged);
  // Its criteria overflow (measured: natural-map residual 1.3e240 N): the test's floating point
  // traps are off for this evaluation, as in any cps run.
  const int traps = fedisableexcept(FE_ALL_EXCEPT);
  const analysis::Criteria jacobi_1000 = analysis::evaluate(s, exact, solve_sweeps(s, SolverKind::jacobi, 1000));
  std::feclearexcept(FE_ALL_EXCEPT);
  feenableexcept(traps);
  CHECK(jacobi_1000.diverged);
  CHECK(std::isinf(jacobi_1000.lambda_error_relative));
  CHECK(std::isinf(jacobi_1000.velocity_error_mps));
  CHECK(analysis::csv_fields(jacobi_1000).find("nan") == std::string::npos);
}

TEST_CASE("the exact solve solves the 4-box stack's degenerate steps from the proximal point start",
          "[exact]") {
  // Four cubes from 1 to 8 kg (the mass ratio scorecard's 4-box case at 8:1), every step solved
  // exactly at the scorecard's tolerance (1e-6 of the force scale). The corner rows of faces
  // resting on faces make A singular or nearly so: in some steps Lemke stops at its pivot limit
  // or its polished solution misses the tolerance, and so does the polish from PGS (measured:
  // step 31, 1.1e-3 and 1.3e-3 N against a force scale of 70 N), while the proximal point start
  // gets there. Each such solution is checked by the criteria, as a solution: natural map and
  // Signorini within the tolerance of the force scale.
  constexpr double kTolerance = 1e-6;
  World world(scenes::mass_ratio_world_def());
  scenes::populate_mass_ratio_stack(world, 8.0, 4);
  std::vector<StepSystem> proximal;
  std::vector<std::string> refused;
  world.set_solve_override([&](const StepSystem& s, Eigen::VectorXd& lambda) {
    try {
      const analysis::ExactSolution exact = analysis::solve_exact(s, kTolerance);
      lambda = exact.lambda;
      if (exact.method == "proximal point start + polish") proximal.push_back(s);
    } catch (const std::runtime_error& e) {
      refused.push_back("step " + std::to_string(s.step) + ": " + e.what());
      lambda = s.initial;
    }
  });
  while (world.time() < 1.0 - 1e-9) world.step();
  for (const std::string& why : refused) FAIL_CHECK(why);
  REQUIRE(!proximal.empty());
  for (const StepSystem& s : proximal) {
    const analysis::ExactSolution exact = analysis::solve_exact(s, kTolerance);
    const analysis::Criteria c = analysis::evaluate(s, exact, exact.lambda);
    const double force_tol = kTolerance * force_scale(s, exact.lambda);
    INFO("step " << s.step << ", rows " << s.rows() << ", force scale "
                 << force_scale(s, exact.lambda) << " N");
    CHECK(c.natural_map_N <= force_tol);
    CHECK(c.signorini_force_N <= force_tol);
    CHECK(c.signorini_velocity_mps <= s.dt * largest_diagonal(s) * force_tol);
    CHECK(c.friction_violation_N <= force_tol);
    CHECK(exact.lambda.maxCoeff() > 1.0);
  }
}
