// Graph-coloured projected Gauss-Seidel (SolverKind::coloured_pgs, engine/src/row_colours.h):
// its order is a Gauss-Seidel order (every row once a sweep, a colour's runs on disjoint movable
// bodies), its solve reaches the solution of the same LCP as PGS, the engine's sweeps on a
// captured system give back the engine's lambda, and every thread count gives the same state.
#include "capture.h"
#include "constraint_solver.h"
#include "matrix_free.h"
#include "row_colours.h"
#include "scene.h"
#include "skip.h"
#include "state_hash.h"
#include "workers.h"

#include "cps/step_system.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

using namespace cps;

namespace {

// The system of `step`'s first solve of a built-in scene under `solver` (matrix-free).
StepSystem capture(const char* scene, std::int64_t step, SolverKind solver) {
  scenes::Overrides o;
  o.set("solver", solver);
  return test::capture(scene, step, o);
}

// pyramid_100 after 30 steps: boxes on boxes and on the ground (static), 4 to 8 points a
// manifold, friction rows that read their contact row's lambda.
scenes::Run settled_pile() {
  scenes::Run run = scenes::make_run(*scenes::find_scene("pyramid_100"));
  for (int k = 0; k < 30; ++k) run.step();
  return run;
}

// f_ext of the run's bodies (6n): gravity on each movable body (N), 0 on static ones.
Eigen::VectorXd gravity_forces(const scenes::Run& run) {
  const std::vector<Body>& bodies = run.world.bodies();
  Eigen::VectorXd f_ext = Eigen::VectorXd::Zero(6 * static_cast<Eigen::Index>(bodies.size()));
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies[i].is_static()) f_ext.segment<3>(6 * static_cast<Eigen::Index>(i)) = bodies[i].mass * run.world.def().gravity;
  }
  return f_ext;
}

// 40 bodies, every fourth static, and 20,000 rows in stretches on one pair of 1 to 60 rows
// (longer than a run may be) and two of 7,000, some against the world: the rows and the same
// stretches as spans. Stretches that follow on the same pair make one run.
struct Stretches {
  std::vector<Body> bodies;
  std::vector<RowSpan> spans;
  std::vector<ConstraintRow> rows;
};

Stretches random_stretches() {
  Stretches out;
  out.bodies.resize(40);
  for (std::size_t i = 0; i < out.bodies.size(); ++i) out.bodies[i].inv_mass = i % 4 == 0 ? 0.0 : 1.0;
  std::mt19937 random(7);
  std::uniform_int_distribution<int> body(0, 39);
  std::uniform_int_distribution<int> length(1, 60);
  for (int stretch = 0; out.rows.size() < 20000; ++stretch) {
    const int a = body(random);
    int b = body(random);
    if (b == a || b % 5 == 0) b = kWorldBody;
    const std::size_t n = stretch == 50 || stretch == 250 ? 7000 : static_cast<std::size_t>(length(random));
    ConstraintRow row;
    row.body_a = stretch % 2 == 0 ? a : b;
    row.body_b = stretch % 2 == 0 ? b : a;
    out.rows.insert(out.rows.end(), n, row);
    out.spans.push_back(RowSpan{row.body_a, row.body_b, static_cast<int>(n)});
  }
  return out;
}

// Block runs swept one by one, not side by side in lanes, while it lives.
struct LanesOff {
  LanesOff() { detail::allow_coloured_lanes(false); }
  ~LanesOff() { detail::allow_coloured_lanes(true); }
  LanesOff(const LanesOff&) = delete;
  LanesOff& operator=(const LanesOff&) = delete;
};

}  // namespace

TEST_CASE("coloured PGS sweeps every row once, and a colour's runs share no movable body",
          "[coloured]") {
  scenes::Run run = settled_pile();
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

TEST_CASE("coloured PGS cuts the rows into the longest runs on one pair that a run may be",
          "[coloured]") {
  const Stretches stretches = random_stretches();
  const std::vector<Body>& bodies = stretches.bodies;
  const std::vector<ConstraintRow>& rows = stretches.rows;
  const auto moving = [&](int b) {
    return b == kWorldBody || bodies[static_cast<std::size_t>(b)].is_static() ? -1 : b;
  };
  // A row's movable bodies in its order, a static body or the world last (a run's a and b).
  const auto pair_of = [&](std::size_t r) {
    const int a = moving(rows[r].body_a);
    const int b = moving(rows[r].body_b);
    return a < 0 ? std::pair{b, a} : std::pair{a, b};
  };
  RowColours colours;
  colour_rows(rows, bodies, MatrixFreeSystem::kMaxRun, colours);
  // The runs tile the rows in order, each on one pair, and each ends at the longest a run may be
  // or where the pair changes.
  std::size_t next = 0;
  for (const RowColours::Run& x : colours.runs) {
    REQUIRE(static_cast<std::size_t>(x.begin) == next);
    REQUIRE(x.count >= 1);
    REQUIRE(x.count <= MatrixFreeSystem::kMaxRun);
    next += static_cast<std::size_t>(x.count);
    for (std::size_t r = static_cast<std::size_t>(x.begin); r < next; ++r) {
      REQUIRE(pair_of(r) == std::pair{x.a, x.b});
    }
    if (x.count < MatrixFreeSystem::kMaxRun && next < rows.size()) REQUIRE(pair_of(next) != pair_of(next - 1));
  }
  REQUIRE(next == rows.size());
}

TEST_CASE("coloured PGS cuts the same runs from the row builder's spans as from the rows",
          "[coloured]") {
  SECTION("stretches on random pairs, longer and shorter than a run") {
    const Stretches stretches = random_stretches();
    RowColours from_rows;
    RowColours from_spans;
    colour_rows(stretches.rows, stretches.bodies, MatrixFreeSystem::kMaxRun, from_rows);
    colour_spans(stretches.spans, stretches.rows.size(), stretches.bodies, MatrixFreeSystem::kMaxRun, from_spans);
    REQUIRE(from_spans.runs.size() == from_rows.runs.size());
    for (std::size_t i = 0; i < from_rows.runs.size(); ++i) {
      const RowColours::Run& x = from_rows.runs[i];
      const RowColours::Run& y = from_spans.runs[i];
      REQUIRE(std::tuple{y.begin, y.count, y.a, y.b} == std::tuple{x.begin, x.count, x.a, x.b});
    }
    CHECK(from_spans.colours == from_rows.colours);
    CHECK(from_spans.order == from_rows.order);
    CHECK(from_spans.start == from_rows.start);
    // Spans that do not cover the rows, or an empty span, are refused.
    CHECK_THROWS_AS(colour_spans(stretches.spans, stretches.rows.size() + 1, stretches.bodies,
                                 MatrixFreeSystem::kMaxRun, from_spans),
                    std::invalid_argument);
    std::vector<RowSpan> empty_span = stretches.spans;
    empty_span.push_back(RowSpan{0, 1, 0});
    CHECK_THROWS_AS(colour_spans(empty_span, stretches.rows.size(), stretches.bodies,
                                 MatrixFreeSystem::kMaxRun, from_spans),
                    std::invalid_argument);
  }
  SECTION("a world's steps: the sweep order of its solve is that of its rows' cut") {
    // Boxes on boxes and the static ground, balls on the funnel's static walls, balls on rods to
    // the world, chains of rods between bodies, a random pile: the row builder's spans give the
    // order that cutting its rows gives.
    // Lanes off, so that the matrix-free order is the colours' runs in order too.
    const LanesOff lanes_off;
    for (const char* scene : {"pyramid_100", "funnel", "pendulum_grid", "chain_20", "heavy_rope", "random"}) {
      CAPTURE(scene);
      scenes::Overrides o;
      o.set("solver", SolverKind::coloured_pgs);
      scenes::Run run = scenes::make_run(*scenes::find_scene(scene), o);
      std::vector<int> swept;
      run.world.set_solve_observer([&](const StepSystem& s) {
        if (s.solve == 0) swept = s.order;
      });
      for (int step = 0; step < 40; ++step) {
        swept.clear();
        run.step();
        RowColours colours;
        std::vector<int> cut;
        colour_rows(run.world.rows(), run.world.bodies(), MatrixFreeSystem::kMaxRun, colours);
        sweep_order(colours, cut);
        REQUIRE(swept == cut);
      }
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

TEST_CASE("coloured PGS forms f = f_ext + J^T lambda from w, the sum over the rows to round-off",
          "[coloured]") {
  // The pile, one solve with the paper's 25 sweeps. The coloured sweeps keep
  // w = M^-1 J^T lambda per body, so f_c = M w (Eq. 6.2.1) is formed per body, not summed over
  // the rows again. The two differ by the round-off of w's additions: each of the 25 sweeps adds
  // a row's change to w once per half, a few eps of the entry's magnitude each, so an entry is
  // within 1e-10 of the sum of |lambda_r j_r| and |f_ext| that makes it (about 1e5 times that
  // round-off). A wrong mass or inertia, or a missing row, is off by the force itself.
  scenes::Run run = settled_pile();
  const std::vector<ConstraintRow>& rows = run.world.rows();
  const std::vector<Body>& bodies = run.world.bodies();
  REQUIRE(rows.size() > 1000);
  const auto n = static_cast<Eigen::Index>(bodies.size());
  const Eigen::VectorXd f_ext = gravity_forces(run);
  // The scale of each entry: |f_ext| plus the magnitudes of the terms of J^T lambda.
  const auto scale = [&](const std::vector<double>& lambda) {
    Eigen::VectorXd out = f_ext.cwiseAbs();
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const ConstraintRow& row = rows[r];
      if (row.body_a != kWorldBody) out.segment<6>(6 * row.body_a) += std::abs(lambda[r]) * row.j.head<6>().cwiseAbs();
      if (row.body_b != kWorldBody) out.segment<6>(6 * row.body_b) += std::abs(lambda[r]) * row.j.tail<6>().cwiseAbs();
    }
    return out;
  };
  Workers two(2);
  for (Workers* workers : {static_cast<Workers*>(nullptr), &two}) {
    CAPTURE(workers != nullptr ? workers->count() : 1);
    MatrixFreeSystem s;
    prepare(s, rows, bodies, SolverKind::coloured_pgs, workers);
    rhs(s, rows, bodies, f_ext, run.world.def().dt, TargetTerms::push_and_bias, workers);
    std::vector<double> lambda;
    solve(s, rows, FrictionModel::fixed, SolverKind::coloured_pgs, 25, lambda, nullptr, workers);
    Eigen::VectorXd from_rows;
    add_constraint_forces(rows, lambda, f_ext, from_rows);
    Eigen::VectorXd from_w;
    constraint_forces(s, bodies, f_ext, from_w, workers);
    REQUIRE(from_w.size() == from_rows.size());
    const Eigen::VectorXd bound = 1e-10 * scale(lambda);
    std::size_t pushed = 0;  // movable bodies that rows push
    for (Eigen::Index i = 0; i < n; ++i) {
      const Body& body = bodies[static_cast<std::size_t>(i)];
      CAPTURE(i);
      if (body.is_static()) {  // nothing moves it: f_ext alone
        CHECK(from_w.segment<6>(6 * i) == f_ext.segment<6>(6 * i));
        continue;
      }
      if ((from_rows.segment<6>(6 * i) - f_ext.segment<6>(6 * i)).norm() > 0.1 * body.mass) ++pushed;
      for (Eigen::Index e = 6 * i; e < 6 * i + 6; ++e) CHECK(std::abs(from_w[e] - from_rows[e]) <= bound[e]);
    }
    CHECK(pushed > 50);  // the rows carry real forces, so the comparison means something
  }
}

TEST_CASE("rows stored in float: j, M^-1 j^T, the limits and mu rounded to the nearest float, the "
          "system they make solved consistently, the same state on every thread count",
          "[coloured][float]") {
  // The pile packed for coloured PGS in double and in float.
  scenes::Run run = settled_pile();
  const std::vector<ConstraintRow>& rows = run.world.rows();
  const std::vector<Body>& bodies = run.world.bodies();
  REQUIRE(rows.size() > 1000);
  MatrixFreeSystem d;
  MatrixFreeSystem f;
  prepare(d, rows, bodies, SolverKind::coloured_pgs, nullptr, RowPrecision::double_precision);
  prepare(f, rows, bodies, SolverKind::coloured_pgs, nullptr, RowPrecision::single_precision);
  REQUIRE(f.rows.empty());
  REQUIRE(d.float_rows.empty());
  REQUIRE(f.float_rows.size() == d.rows.size());
  // Round to nearest: each number within half a float ulp, 2^-24 of itself (IEEE 754).
  const double half_ulp = std::ldexp(1.0, -24);
  for (std::size_t i = 0; i < d.rows.size(); ++i) {
    const MatrixFreeSystem::Row& x = d.rows[i];
    const MatrixFreeSystem::FloatRow& y = f.float_rows[i];
    CAPTURE(i);
    REQUIRE((x.a == y.a && x.b == y.b && x.normal_row == y.normal_row));
    // The bounds and mu rounded too (an infinite bound stays infinite).
    for (const auto& [exact, rounded] : {std::pair{x.c_min, y.c_min}, std::pair{x.c_max, y.c_max}, std::pair{x.mu, y.mu}}) {
      if (std::isinf(exact)) {
        CHECK(static_cast<double>(rounded) == exact);
      } else {
        CHECK(std::abs(static_cast<double>(rounded) - exact) <= half_ulp * std::abs(exact));
      }
    }
    double terms = 0.0;  // sum of |j_k (M^-1 j^T)_k|: A_jj's terms
    for (std::size_t e = 0; e < 12; ++e) {
      CHECK(std::abs(static_cast<double>(y.j[e]) - x.j[e]) <= half_ulp * std::abs(x.j[e]));
      CHECK(std::abs(static_cast<double>(y.minv_jt[e]) - x.minv_jt[e]) <= half_ulp * std::abs(x.minv_jt[e]));
      terms += std::abs(x.j[e] * x.minv_jt[e]);
    }
    // A_jj of the stored numbers: each product off by at most two roundings of 2^-24.
    if (x.inv_diagonal > 0.0) {
      CHECK(std::abs(1.0 / y.inv_diagonal - 1.0 / x.inv_diagonal) <= 3.0 * half_ulp * terms);
    }
  }
  // The engine's float sweeps on the captured system (A from the stored floats) give its lambda
  // back to round-off: the rows, A_jj and the coupling all come from the same numbers.
  {
    scenes::Overrides o;
    o.set("solver", SolverKind::coloured_pgs);
    o.set("row_precision", RowPrecision::single_precision);
    const StepSystem s = test::capture("funnel", 180, o);
    REQUIRE(s.rows() > 0);
    const Eigen::VectorXd again = solve_sweeps(s, SolverKind::coloured_pgs, s.iterations, &s.initial);
    CHECK((again - s.lambda).cwiseAbs().maxCoeff() <= 1e-9 * s.lambda.cwiseAbs().maxCoeff());
  }
  // The same state on 1, 2 and 3 threads, and not double's.
  std::uint64_t hashes[4] = {};
  for (int threads = 0; threads <= 3; ++threads) {
    scenes::Overrides o;
    o.set("solver", SolverKind::coloured_pgs);
    o.set("row_precision", threads == 0 ? RowPrecision::double_precision : RowPrecision::single_precision);
    o.set("threads", std::max(threads, 1));
    scenes::Run r = scenes::make_run(*scenes::find_scene("pyramid_100"), o);
    for (int k = 0; k < 60; ++k) r.world.step();
    hashes[threads] = scenes::state_hash(r.world);
  }
  CHECK(hashes[1] != hashes[0]);
  CHECK(hashes[2] == hashes[1]);
  CHECK(hashes[3] == hashes[1]);
  // The explicit path assembles J in double: float rows are refused there, naming both.
  WorldDef def;
  def.assembly = Assembly::explicit_matrices;
  def.row_precision = RowPrecision::single_precision;
  CHECK_THROWS_WITH(def.validate(), Catch::Contains("row_precision = float") && Catch::Contains("explicit"));
}

TEST_CASE("coloured PGS ends in the same state on 1, 2 and 3 threads", "[coloured][threads]") {
  // The runs of a colour share no movable body and the threads claim blocks of every colour
  // between barriers, so the floating-point results are the same for every thread count and
  // schedule: the state hash after 60 steps is equal bit for bit. Piles (contacts, coupled
  // friction, warm started; pyramid_300's colours are cut into several blocks) and a chain of
  // rods, under the paper's push and the single frame push factor (two solves a step).
  for (const char* name : {"pyramid_100", "pyramid_300", "chain_20"}) {
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

TEST_CASE("BlockClaims hands every block of every stage to exactly one thread", "[threads]") {
  // Stages of 1 to the most blocks, on 1 to 4 threads, thread 0 held back by extra work in
  // some stages so that the others may claim from its share, in two tasks: each block's claims
  // are counted.
  for (int threads = 1; threads <= 4; ++threads) {
    CAPTURE(threads);
    Workers workers(threads);
    const std::size_t most = workers.max_blocks();
    constexpr int kStages = 200;
    std::vector<std::atomic<int>> claimed(static_cast<std::size_t>(kStages) * most);
    for (int task = 0; task < 2; ++task) {  // the stamps carry over from task to task
      for (auto& c : claimed) c.store(0);
      auto run = [&](int t) {
        BlockClaims claims(workers, t);
        for (int k = 0; k < kStages; ++k) {
          const std::size_t blocks = 1 + static_cast<std::size_t>(k) % most;
          claims.stage(blocks);
          for (std::size_t block; claims.next(block);) {
            claimed[static_cast<std::size_t>(k) * most + block].fetch_add(1);
            if (t == 0 && k % 3 == 0) {  // a slow thread: busy work, no clock
              volatile double x = 1.0;
              for (int i = 0; i < 20000; ++i) x = x * 1.0000001;
            }
          }
          workers.sync();
        }
      };
      workers.run(run);
      int wrong = 0;
      for (int k = 0; k < kStages; ++k) {
        const std::size_t blocks = 1 + static_cast<std::size_t>(k) % most;
        for (std::size_t b = 0; b < most; ++b) {
          const int n = claimed[static_cast<std::size_t>(k) * most + b].load();
          if (n != (b < blocks ? 1 : 0)) ++wrong;
        }
      }
      CHECK(wrong == 0);
    }
  }
}

TEST_CASE("parallel_blocks hands every item to exactly one call, in ranges within the items",
          "[threads]") {
  // Counts below the sharing threshold, below, at and past the most blocks, and a large odd one,
  // with no workers and on 1 to 4 threads: each item's calls are counted.
  constexpr std::size_t kMinParallel = 4;
  for (int threads = 0; threads <= 4; ++threads) {  // 0: no workers
    CAPTURE(threads);
    std::optional<Workers> pool;
    if (threads > 0) pool.emplace(threads);
    Workers* workers = pool ? &*pool : nullptr;
    const std::size_t most = pool ? pool->max_blocks() : 8;
    for (const std::size_t count : {std::size_t{0}, std::size_t{1}, kMinParallel - 1, kMinParallel, most - 1,
                                    most, most + 1, std::size_t{10007}}) {
      CAPTURE(count);
      std::vector<std::atomic<int>> calls(count);
      std::atomic<int> bad_ranges{0};
      parallel_blocks(workers, count, kMinParallel, [&](std::size_t begin, std::size_t end) {
        if (begin > end || end > count) {
          bad_ranges.fetch_add(1);
          return;
        }
        for (std::size_t i = begin; i < end; ++i) calls[i].fetch_add(1);
      });
      CHECK(bad_ranges.load() == 0);
      int wrong = 0;
      for (const auto& c : calls) wrong += c.load() == 1 ? 0 : 1;
      CHECK(wrong == 0);
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

TEST_CASE("the coupling blocks the first sweep forms are A_ki / A_kk, and a later solve of the same "
          "rows reuses them to the same lambda",
          "[coloured][pgs]") {
  // Each block run's coupling (A_ki / A_kk for its rows k after i) is formed by the first sweep of
  // the first solve after prepare(). It must hold j_k . M^-1 j_i^T / A_kk of the packed rows (here
  // the 12 products summed in another order; each order is within 11 eps of the sum of their
  // magnitudes, so the two within 16 eps of it after the product with 1 / A_kk), and a second
  // solve from 0 must give the first's lambda bit for bit.
  scenes::Run run = settled_pile();
  const std::vector<ConstraintRow>& rows = run.world.rows();
  const std::vector<Body>& bodies = run.world.bodies();
  REQUIRE(rows.size() > 1000);
  const Eigen::VectorXd f_ext = gravity_forces(run);
  for (SolverKind kind : {SolverKind::pgs, SolverKind::coloured_pgs}) {
    CAPTURE(name_of(kind));
    MatrixFreeSystem s;
    prepare(s, rows, bodies, kind);
    rhs(s, rows, bodies, f_ext, run.world.def().dt, TargetTerms::push_and_bias);
    std::vector<double> first;
    solve(s, rows, FrictionModel::coupled, kind, 25, first);
    std::size_t blocks = 0;
    const double eps = std::numeric_limits<double>::epsilon();
    std::size_t lane_groups = 0;
    for (const MatrixFreeSystem::Run& r : s.runs) {
      if (r.offset < 0 || s.rows[static_cast<std::size_t>(r.begin)].a == static_cast<int>(bodies.size())) continue;
      ++blocks;
      if (r.lanes > 1) ++lane_groups;
      // A lane group's runs interleaved: row i of lane L at begin + lanes i + L, entry e at
      // offset + lanes e + L.
      for (int lane = 0; lane < r.lanes; ++lane) {
        const auto row = [&](int i) -> const MatrixFreeSystem::Row& {
          return s.rows[static_cast<std::size_t>(r.begin + r.lanes * i + lane)];
        };
        const double* g = s.coupling.data() + r.offset + lane;
        for (int i = 0; i < r.count; g += r.lanes * (r.count - 1 - i), ++i) {
          const MatrixFreeSystem::Row& ri = row(i);
          for (int k = i + 1; k < r.count; ++k) {
            const MatrixFreeSystem::Row& rk = row(k);
            REQUIRE(rk.a == ri.a);  // one run: the same two bodies
            REQUIRE(rk.b == ri.b);
            double a_ki = 0.0;
            double terms = 0.0;
            for (std::size_t e = 0; e < 12; ++e) {
              a_ki += rk.j[e] * ri.minv_jt[e];
              terms += std::abs(rk.j[e] * ri.minv_jt[e]);
            }
            CHECK(std::abs(g[r.lanes * (k - i - 1)] - a_ki * rk.inv_diagonal) <= 16.0 * eps * terms * rk.inv_diagonal);
          }
        }
      }
    }
    CHECK(blocks > 100);  // the pile's manifolds are blocks, so the check above means something
    // Coloured PGS puts most of them side by side in lane groups; PGS never does.
    if (kind == SolverKind::coloured_pgs) {
      CHECK(lane_groups * 2 > blocks);
    } else {
      CHECK(lane_groups == 0);
    }
    std::vector<double> again;
    solve(s, rows, FrictionModel::coupled, kind, 25, again);
    CHECK(again == first);
  }
}

TEST_CASE("coloured PGS's sweeps give the same state built for the baseline and for AVX2",
          "[coloured][simd]") {
  // The block sweep runs on 4-wide vectors: two SSE2 registers in the baseline build, one AVX2
  // register where the CPU has it. Each lane's operations and the order of every sum are the
  // same, so both must end in the same state bit for bit (double and float rows, coupled
  // friction, 2 threads).
#if defined(__x86_64__)
  if (!__builtin_cpu_supports("avx2")) CPS_SKIP("this CPU has no AVX2, so only the baseline build runs");
#else
  CPS_SKIP("the AVX2 build exists on x86-64 only");
#endif
  for (RowPrecision precision : {RowPrecision::double_precision, RowPrecision::single_precision}) {
    std::uint64_t hashes[2] = {};
    for (int avx2 = 0; avx2 < 2; ++avx2) {
      detail::allow_coloured_avx2(avx2 == 1);
      scenes::Overrides o;
      o.set("solver", SolverKind::coloured_pgs);
      o.set("row_precision", precision);
      o.set("friction_model", FrictionModel::coupled);
      o.set("threads", 2);
      scenes::Run r = scenes::make_run(*scenes::find_scene("pyramid_100"), o);
      for (int k = 0; k < 60; ++k) r.world.step();
      hashes[avx2] = scenes::state_hash(r.world);
    }
    detail::allow_coloured_avx2(true);
    CHECK(hashes[0] == hashes[1]);
  }
}

TEST_CASE("coloured PGS gives the same state with block runs side by side in lanes as one by one",
          "[coloured][simd]") {
  // A lane group sweeps four runs of one colour at once, each in its lane, with each lane's
  // operations those of the run swept alone; the runs of a colour share no movable body, so the
  // order they are taken in changes nothing. So the state must be the same bit for bit: double
  // and float rows, fixed and coupled friction, from 0 and warm started, on 1 and 2 threads.
  struct Case {
    RowPrecision precision;
    FrictionModel friction;
    double warm_start;
    int threads;
  };
  const Case cases[] = {
      {RowPrecision::single_precision, FrictionModel::fixed, 0.0, 1},
      {RowPrecision::double_precision, FrictionModel::coupled, 0.0, 2},
      {RowPrecision::single_precision, FrictionModel::coupled, 1.0, 1},
      {RowPrecision::double_precision, FrictionModel::fixed, 0.8, 2},
  };
  for (const Case& c : cases) {
    CAPTURE(static_cast<int>(c.precision), static_cast<int>(c.friction), c.warm_start, c.threads);
    std::uint64_t hashes[2] = {};
    for (int lanes = 0; lanes < 2; ++lanes) {
      detail::allow_coloured_lanes(lanes == 1);
      scenes::Overrides o;
      o.set("solver", SolverKind::coloured_pgs);
      o.set("row_precision", c.precision);
      o.set("friction_model", c.friction);
      o.set("warm_start", c.warm_start);
      o.set("threads", c.threads);
      scenes::Run r = scenes::make_run(*scenes::find_scene("pyramid_100"), o);
      for (int k = 0; k < 60; ++k) r.world.step();
      hashes[lanes] = scenes::state_hash(r.world);
      for (const Body& body : r.world.bodies()) REQUIRE(body.x.allFinite());  // equal, and not both NaN
    }
    detail::allow_coloured_lanes(true);
    CHECK(hashes[0] == hashes[1]);
  }
}

TEST_CASE("coloured PGS's lane groups keep a row that touches no movable body at 0, and give the "
          "others the numbers of the runs swept one by one",
          "[coloured][simd]") {
  // Eight boxes on a static ground, each with a run of rows on (box, ground): four runs of 4 rows
  // and four of 5, so that coloured PGS sweeps them in two lane groups (the runs share no movable
  // body). In one run of each group one row's j is 0 on the box: A_jj = 0, a row that touches no
  // movable body, whose lambda stays 0 (as solve_lcp) while its lane's other rows and the other
  // lanes go on. So the lambda must be the same bit for bit with lanes and without, with 0 there.
  std::vector<Body> bodies;
  for (int k = 0; k < 8; ++k) {
    BodyDef def{Shape::box(Vec3(0.5, 0.5, 0.5)), false, 1.0 + k, Vec3(3.0 * k, 0.5, 0.0)};
    bodies.push_back(make_body(def));
  }
  bodies.push_back(make_body({Shape::plane(Vec3::UnitY(), 0.0), true}));
  const int ground = 8;
  std::vector<ConstraintRow> rows;
  std::vector<std::size_t> empty;  // the rows with j = 0 on the box
  for (int k = 0; k < 8; ++k) {
    const int count = k < 4 ? 4 : 5;
    for (int p = 0; p < count; ++p) {
      ConstraintRow row;
      row.body_a = k;
      row.body_b = ground;
      // A contact row along the ground's normal at a corner of the box's base, a friction-like
      // row along x at the last one.
      const Vec3 r_a(p % 2 == 0 ? -0.5 : 0.5, -0.5, p < 2 ? -0.5 : 0.5);
      const Vec3 n = p == 4 ? Vec3::UnitX() : Vec3::UnitY();
      row.j = axis_row(n, r_a, Vec3(3.0 * k, 0.0, 0.0) + r_a);
      row.c_min = p == 4 ? -2.0 : 0.0;
      row.c_max = p == 4 ? 2.0 : kInfinity;
      row.bias = 0.01 * (p + 1);
      if ((k == 2 || k == 5) && p == 1) {
        row.j.head<6>().setZero();
        row.c_min = 1.0;  // bounds without 0: clamped, lambda would move off 0
        row.c_max = 2.0;
        empty.push_back(rows.size());
      }
      rows.push_back(row);
    }
  }
  Eigen::VectorXd f_ext = Eigen::VectorXd::Zero(6 * static_cast<Eigen::Index>(bodies.size()));
  for (int k = 0; k < 8; ++k) f_ext[6 * k + 1] = -9.81 * bodies[static_cast<std::size_t>(k)].mass;
  for (const RowPrecision precision : {RowPrecision::double_precision, RowPrecision::single_precision}) {
    for (const FrictionModel friction : {FrictionModel::fixed, FrictionModel::coupled}) {
      CAPTURE(static_cast<int>(precision), static_cast<int>(friction));
      std::vector<double> lambda[2];
      for (int lanes = 0; lanes < 2; ++lanes) {
        detail::allow_coloured_lanes(lanes == 1);
        MatrixFreeSystem s;
        prepare(s, rows, bodies, SolverKind::coloured_pgs, nullptr, precision);
        rhs(s, rows, bodies, f_ext, 1.0 / 60.0, TargetTerms::push_and_bias);
        int grouped = 0;  // runs in lane groups
        for (const MatrixFreeSystem::Run& run : s.runs) grouped += run.lanes > 1 ? run.lanes : 0;
        CHECK(grouped == (lanes == 1 ? 8 : 0));
        solve(s, rows, friction, SolverKind::coloured_pgs, 10, lambda[lanes]);
      }
      detail::allow_coloured_lanes(true);
      CHECK(lambda[1] == lambda[0]);
      for (const std::size_t e : empty) CHECK(lambda[1][e] == 0.0);
      // The rows carry the boxes' weight, so the comparison means something.
      CHECK(*std::max_element(lambda[1].begin(), lambda[1].end()) > 1.0);
    }
  }
}
