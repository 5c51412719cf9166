// Graph-coloured projected Gauss-Seidel (SolverKind::coloured_pgs, engine/src/row_colours.h):
// its order is a Gauss-Seidel order (every row once a sweep, a colour's runs on disjoint movable
// bodies), its solve reaches the solution of the same LCP as PGS, the engine's sweeps on a
// captured system give back the engine's lambda, and every thread count gives the same state.
#include "capture.h"
#include "matrix_free.h"
#include "row_colours.h"
#include "scene.h"
#include "state_hash.h"

#include "cps/step_system.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

using namespace cps;

namespace {

// The system of `step`'s first solve of a built-in scene under `solver` (matrix-free).
StepSystem capture(const char* scene, std::int64_t step, SolverKind solver) {
  scenes::Overrides o;
  o.set("solver", solver);
  return test::capture(scene, step, o);
}

}  // namespace

TEST_CASE("coloured PGS sweeps every row once, and a colour's runs share no movable body",
          "[coloured]") {
  // pyramid_100 after 30 steps: boxes on boxes and on the ground (static), 4 to 8 points a
  // manifold, friction rows that read their contact row's lambda.
  scenes::Run run = scenes::make_run(*scenes::find_scene("pyramid_100"));
  for (int k = 0; k < 30; ++k) run.step();
  const std::vector<ConstraintRow>& rows = run.world.rows();
  REQUIRE(rows.size() > 1000);
  RowColours colours;
  colour_rows(rows, run.world.bodies(), MatrixFreeSystem::kMaxRun, colours);
  std::vector<int> order;
  sweep_order(colours, order);
  // A permutation of the rows.
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  REQUIRE(sorted.size() == rows.size());
  for (std::size_t i = 0; i < sorted.size(); ++i) REQUIRE(sorted[i] == static_cast<int>(i));
  const auto moving = [&](int body) {
    return body == kWorldBody || run.world.bodies()[static_cast<std::size_t>(body)].is_static() ? -1 : body;
  };
  std::vector<int> run_of(rows.size(), -1);
  for (std::size_t r = 0; r < colours.runs.size(); ++r) {
    const RowColours::Run& x = colours.runs[r];
    CHECK(x.count >= 1);
    CHECK(x.count <= MatrixFreeSystem::kMaxRun);
    for (int i = x.begin; i < x.begin + x.count; ++i) {
      run_of[static_cast<std::size_t>(i)] = static_cast<int>(r);
      const ConstraintRow& row = rows[static_cast<std::size_t>(i)];
      // The run's bodies are the row's movable ones.
      CHECK(std::set<int>{moving(row.body_a), moving(row.body_b)} == std::set<int>{x.a, x.b});
    }
  }
  int coloured_runs = 0;
  for (int c = 0; c < ConstraintGraph::kOverflow; ++c) {
    std::set<int> bodies;
    for (std::size_t i = colours.start[c]; i < colours.start[c + 1]; ++i) {
      const RowColours::Run& x = colours.runs[colours.order[i]];
      CHECK(colours.colours[colours.order[i]] == c);
      for (const int body : {x.a, x.b}) {
        if (body < 0) continue;
        CHECK(bodies.insert(body).second);  // no other run of this colour moves it
      }
      ++coloured_runs;
    }
  }
  CHECK(coloured_runs > 0);
  // A friction row reads its contact row's lambda: in its own run, or in a run of another
  // colour (never one swept at the same time).
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (rows[r].normal_row < 0) continue;
    const int mine = run_of[r];
    const int theirs = run_of[static_cast<std::size_t>(rows[r].normal_row)];
    if (mine != theirs) {
      CHECK(colours.colours[static_cast<std::size_t>(mine)] != colours.colours[static_cast<std::size_t>(theirs)]);
    }
  }
}

TEST_CASE("coloured PGS solves the same LCP as PGS: the engine's sweeps on the captured system "
          "give its lambda back, and many sweeps reach the solution",
          "[coloured][exact]") {
  // The funnel at 3 s: spheres on spheres and on the funnel's static walls.
  for (const char* scene : {"stack", "funnel"}) {
    CAPTURE(scene);
    const StepSystem s = capture(scene, 180, SolverKind::coloured_pgs);
    REQUIRE(s.rows() > 0);
    REQUIRE(s.solver == SolverKind::coloured_pgs);
    REQUIRE(s.order.size() == static_cast<std::size_t>(s.rows()));
    // The explicit sweeps in the captured order: the matrix-free lambda to round-off.
    const Eigen::VectorXd again = solve_sweeps(s, SolverKind::coloured_pgs, s.iterations, &s.initial);
    CHECK((again - s.lambda).cwiseAbs().maxCoeff() <= 1e-9 * s.lambda.cwiseAbs().maxCoeff());
    // Both orders converge to a solution of the LCP: the natural-map residual (N) falls to
    // round-off of the largest force. (Not on the stack: its face contacts of 4 coplanar points
    // make A singular, where PGS in any order creeps; 20000 sweeps leave 2.6e-5 N in both.)
    if (std::string(scene) == "stack") continue;
    const double scale = std::max(1.0, s.lambda.cwiseAbs().maxCoeff());
    const Eigen::VectorXd coloured = solve_sweeps(s, SolverKind::coloured_pgs, 20000);
    const Eigen::VectorXd in_order = solve_sweeps(s, SolverKind::pgs, 20000);
    CHECK(natural_map_residual(s, coloured).maxCoeff() <= 1e-8 * scale);
    CHECK(natural_map_residual(s, in_order).maxCoeff() <= 1e-8 * scale);
  }
  // Without its order a captured system cannot be swept in it.
  StepSystem plain = capture("stack", 180, SolverKind::pgs);
  CHECK(plain.order.empty());
  CHECK_THROWS_AS(solve_sweeps(plain, SolverKind::coloured_pgs, 1), std::invalid_argument);
}

TEST_CASE("coloured PGS ends in the same state on 1, 2 and 3 threads", "[coloured][threads]") {
  // The runs of a colour share no movable body and each thread sweeps a share of every colour
  // between barriers, so the floating-point results are the same for every thread count: the
  // state hash after 60 steps is equal bit for bit. A pile (contacts, coupled friction, warm
  // started) and a chain of rods, under the paper's push and the single frame push factor (two
  // solves a step).
  for (const char* name : {"pyramid_100", "chain_20"}) {
    for (const PushMode push : {PushMode::baumgarte, PushMode::split}) {
      CAPTURE(name, static_cast<int>(push));
      std::uint64_t hashes[3] = {};
      for (int threads = 1; threads <= 3; ++threads) {
        scenes::Overrides o;
        o.set("solver", SolverKind::coloured_pgs);
        o.set("push", push);
        o.set("warm_start", 1.0);
        o.set("friction_model", FrictionModel::coupled);
        o.set("threads", threads);
        scenes::Run run = scenes::make_run(*scenes::find_scene(name), o);
        for (int k = 0; k < 60; ++k) run.world.step();
        hashes[threads - 1] = scenes::state_hash(run.world);
      }
      CHECK(hashes[1] == hashes[0]);
      CHECK(hashes[2] == hashes[0]);
    }
  }
}

TEST_CASE("the shared stages end in the same state on 1, 2 and 3 threads", "[threads]") {
  // With --threads N the narrow phase (each thread a share of the pairs, joined in pair order),
  // the packing of the rows and the right-hand side (each row and body its own result) run on N
  // threads under every solver, so the state hash after 40 steps is equal bit for bit, also for
  // the paper's PGS. pyramid_300 has more pairs, rows and bodies than the stages' thresholds for
  // sharing; contact recycling looks up last step's manifolds from each thread's own cursor.
  struct Variant {
    SolverKind solver;
    PushMode push;
    double recycle;  // m
  };
  for (const Variant v : {Variant{SolverKind::pgs, PushMode::baumgarte, 0.0},
                          Variant{SolverKind::pgs, PushMode::baumgarte, 0.02},
                          Variant{SolverKind::coloured_pgs, PushMode::baumgarte, 0.0},
                          Variant{SolverKind::pgs, PushMode::soft, 0.02}}) {
    CAPTURE(static_cast<int>(v.solver), static_cast<int>(v.push), v.recycle);
    std::uint64_t hashes[3] = {};
    std::int64_t recycled = 0;
    for (int threads = 1; threads <= 3; ++threads) {
      scenes::Overrides o;
      o.set("solver", v.solver);
      o.set("push", v.push);
      o.set("warm_start", 1.0);
      o.set("contact_recycle_distance", v.recycle);
      o.set("threads", threads);
      scenes::Run run = scenes::make_run(*scenes::find_scene("pyramid_300"), o);
      for (int k = 0; k < 40; ++k) run.world.step();
      hashes[threads - 1] = scenes::state_hash(run.world);
      if (threads == 1) recycled = run.world.counters().recycled;
      CHECK(run.world.counters().recycled == recycled);
      // Equal hashes of a broken state would prove nothing: every body finite, none through the
      // ground (its centre above it).
      for (const Body& body : run.world.bodies()) {
        if (body.is_static()) continue;
        CHECK(std::isfinite(body.x.squaredNorm() + body.p.squaredNorm() + body.l.squaredNorm()));
        CHECK(body.x.y() > 0.0);
      }
    }
    CHECK((v.recycle == 0.0) == (recycled == 0));  // recycling happened where it is on
    CHECK(hashes[1] == hashes[0]);
    CHECK(hashes[2] == hashes[0]);
  }
}
