// Solver error and time-step error apart (demos/cps/report/references.h): the horizon where two
// references part, the per-step solver error against the exact solution, and the engine's solve
// override (World::set_solve_override) the exact reference steps with.
#include "report/references.h"

#include "exact_lcp.h"
#include "scene.h"
#include "state_hash.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <vector>

using namespace cps;
using namespace cps::cli;

TEST_CASE("the observed order and the finest run's error from three step sizes (Richardson)",
          "[report][references]") {
  // Runs of a method with error C h^p, against the exact solution x*: x(h) = x* + C h^p. The
  // distances between successive halvings give p back and the finest run's error C (h/4)^p.
  for (const double p : {0.26, 0.5, 1.0, 2.0}) {
    const double C = 3.0, h = 0.1;
    const auto x = [&](double step) { return C * std::pow(step, p); };  // error of a run
    const double d_coarse = x(h) - x(h / 2), d_fine = x(h / 2) - x(h / 4);
    const ObservedOrder o = observed_order(d_coarse, d_fine);
    CHECK(o.order == Approx(p).epsilon(1e-12));
    CHECK(o.error == Approx(x(h / 4)).epsilon(1e-12));
    // First order: the error of the finest is the distance itself; below first order, more.
    if (p == 1.0) CHECK(o.error == Approx(d_fine).epsilon(1e-12));
    if (p < 1.0) CHECK(o.error > d_fine);
  }
  // Distances that do not shrink (chaos, or an error that another error dominates) bound nothing.
  CHECK(std::isnan(observed_order(0.1, 0.1).error));
  CHECK(std::isnan(observed_order(0.1, 0.2).error));
  CHECK(observed_order(0.1, 0.2).order == Approx(-1.0));
  // The same positions at both finer steps: no error left.
  CHECK(observed_order(0.1, 0.0).error == 0.0);
  CHECK(std::isnan(observed_order(0.0, 0.0).order));
  CHECK(observed_order(0.0, 0.0).error == 0.0);  // three runs that agree exactly
  CHECK(std::isnan(observed_order(std::nan(""), 0.1).order));
}

TEST_CASE("the local order between two runs is the slope of the error in the count on log axes",
          "[report][references]") {
  // e = C n^-p: doubling n divides the error by 2^p.
  CHECK(local_order(0.8, 1, 0.2, 4) == Approx(1.0));
  CHECK(local_order(0.8, 2, 0.1, 4) == Approx(3.0));
  CHECK(local_order(0.1, 8, 0.2, 16) == Approx(-1.0));  // the error grew
  CHECK(std::isnan(local_order(0.0, 1, 0.1, 2)));
  CHECK(std::isnan(local_order(0.1, 2, 0.1, 2)));
  CHECK(std::isnan(local_order(std::numeric_limits<double>::infinity(), 1, 0.1, 2)));
}

TEST_CASE("the agreement horizon is the last time before the references part", "[report][references]") {
  const std::vector<double> t = {0.1, 0.2, 0.3, 0.4};
  // Two identical references: distance 0 at every step, so they never part.
  CHECK(std::isinf(agreement_horizon(t, {0.0, 0.0, 0.0, 0.0}, 0.01)));
  // Within the tolerance (equal counts as within) until 0.2 s, beyond it at 0.3 s.
  CHECK(agreement_horizon(t, {0.0, 0.01, 0.02, 0.0}, 0.01) == 0.2);
  // Beyond at the first step: no time of agreement.
  CHECK(agreement_horizon(t, {0.5, 0.0, 0.0, 0.0}, 0.01) == 0.0);
  // A reference that is not finite parts at once.
  CHECK(agreement_horizon(t, {0.0, std::nan(""), 0.0, 0.0}, 0.01) == 0.1);
  CHECK(std::isinf(agreement_horizon({}, {}, 0.01)));
  CHECK_THROWS_AS(agreement_horizon(t, {0.0}, 0.01), std::invalid_argument);
}

TEST_CASE("the stack's sampled steps: the exact solution at round-off, PGS closer with more sweeps",
          "[report][references][exact]") {
  int no_solve = -1;
  const std::vector<SolverErrorPoint> points = sample_solver_error(RunSpec{"stack"}, 6, no_solve);
  CHECK(no_solve >= 0);
  // The stack's contact forces are some 10 to 100 N (five 1.2 kg cubes under g = 10 m/s^2);
  // solve_exact refuses a residual above 1e-9 of the force scale, so 1e-7 N is round-off here.
  std::map<std::int64_t, std::map<std::pair<std::string, int>, const SolverErrorPoint*>> by_step;
  int exact = 0;
  for (const SolverErrorPoint& p : points) {
    by_step[p.step][{p.method, p.sweeps}] = &p;
    if (p.method != "exact") continue;
    ++exact;
    CHECK(p.refused.empty());
    CHECK(p.residual_N <= 1e-7);
    CHECK(p.velocity_mps <= 1e-9);
  }
  CHECK(exact >= 4);  // the sampled steps after the first landing have contacts
  for (const auto& [step, at] : by_step) {
    INFO("step " << step);
    const SolverErrorPoint* one = at.at({"pgs", 1});
    const SolverErrorPoint* hundred = at.at({"pgs", 100});
    // PGS decreases the convex quadratic 1/2 l.A l - b.l sweep by sweep (Sec. 7.2), and its
    // velocity error shrinks with it; the force error to the nearest solution follows here.
    CHECK(hundred->velocity_mps <= one->velocity_mps);
    CHECK(hundred->relative <= one->relative);
    CHECK(hundred->residual_N <= one->residual_N);
  }
}

TEST_CASE("the solve override: the engine's own lambda changes nothing, the exact one solves the step",
          "[report][references][exact]") {
  const scenes::Scene& stack = *scenes::find_scene("stack");
  scenes::Overrides o;
  o.set("measure_residual", true);
  // The explicit assembly measures the residual from A and the lambda the step used; the
  // matrix-free path's residual reads the solve's own M^-1 J^T lambda (world.h).
  o.set("assembly", Assembly::explicit_matrices);
  scenes::Run plain = scenes::make_run(stack, o);
  scenes::Run same = scenes::make_run(stack, o);
  same.world.set_solve_override([](const StepSystem&, Eigen::VectorXd&) {});
  scenes::Run exact = scenes::make_run(stack, o);
  long solves = 0;
  bool refused = false;
  exact.world.set_solve_override([&](const StepSystem& s, Eigen::VectorXd& lambda) {
    try {
      lambda = analysis::solve_exact(s).lambda;
      ++solves;
    } catch (const std::runtime_error&) {
      refused = true;  // no exact solution found (see below): the engine's lambda stays
    }
  });
  // To 0.6 s: four cubes land (0.40 to 0.53 s). Should solve_exact refuse a step (neither
  // Lemke's nor the PGS start's polish passes its residual check; the report lists such steps),
  // the residual is judged up to the step before the first refusal.
  double exact_residual = 0.0;
  for (int i = 0; i < 36; ++i) {
    plain.world.step();
    same.world.step();
    if (refused) continue;
    exact.world.step();
    if (!refused) exact_residual = exact.world.residual().max;
  }
  REQUIRE(solves >= 1);
  CHECK(scenes::state_hash(plain.world) == scenes::state_hash(same.world));
  CHECK(solves > 0);
  // The residual the step measures is of the lambda it used: the exact one's is at round-off,
  // PGS's at 25 sweeps is not.
  CHECK(exact_residual <= 1e-7);
  CHECK(plain.world.residual().max > 1e-3);
  // A lambda of the wrong size is refused.
  exact.world.set_solve_override([](const StepSystem&, Eigen::VectorXd& lambda) { lambda.resize(1); });
  CHECK_THROWS_AS(exact.world.step(), std::invalid_argument);
}

TEST_CASE("the stack's two references are checked to its trajectory time: where Lemke stops, the "
          "polish from PGS sweeps passes the residual check",
          "[report][references][exact]") {
  // At 16 substeps Siconos' Lemke cycles to its pivot limit on the stack's step 696 (t = 0.725 s,
  // LCP of size 40: the corner rows of a face are redundant). solve_exact then polishes from
  // 2000 PGS sweeps and accepts only a natural-map residual under 1e-9 of the force scale, so a
  // reference that goes past that step is exact on every step it took.
  const double until = 0.8;  // the stack's trajectory time (s)
  const ReferenceAgreement a = compare_references(RunSpec{"stack"}, until, kAgreementSolves);
  INFO("stopped: " << a.stopped);
  CHECK(a.stopped.empty());
  CHECK(a.checked_until_s >= until - 1e-9);
  // Both references stay within 1 % of a cube (2.4 cm) over the whole time.
  CHECK(std::isinf(a.horizon_s));
}
