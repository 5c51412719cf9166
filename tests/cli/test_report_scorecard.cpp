// The mass ratio scorecard of `cps report push` (report/push/scorecard.h): what it counts as
// holding, the settings each row runs, and the exact solve against the paper's sweeps.
#include "report/push/scorecard.h"

#include "../skip.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace cps;
using namespace cps::cli;

namespace {

ScoreRow row_of(const char* push, ScoreSettings settings, bool exact = false) {
  const std::optional<Method> m = push_method_named(push);
  REQUIRE(m);
  return {.method = *m, .settings = settings, .k_start = std::nullopt, .exact = exact};
}

// Siconos numerics is opened by the first exact solve: a cell refused because it cannot be
// opened is not a result (a refusal for any other reason is, and fails below).
bool siconos_missing(const ScoreCell& c) {
  return !c.held && c.why.find("cannot open Siconos") != std::string::npos;
}

}  // namespace

TEST_CASE("scorecard: the exact solve holds what the paper's 25 sweeps lose, at the same dt",
          "[cli][report][scorecard]") {
  const ScoreRow paper = row_of("baumgarte", ScoreSettings::paper);
  const ScoreRow exact = row_of("baumgarte", ScoreSettings::paper, true);
  // The rope at 2^17: a block of 13,107 kg on 20 links of 0.1 kg. Gauss-Seidel from 0 converges
  // the more slowly the heavier the block (the error of a rod's force next to it shrinks by about
  // R / (1 + R) a sweep, as the mass ratio pair's, stress/mass_ratio.h), so 25 sweeps leave the
  // rods short of carrying it and the block sinks out of place; the exact solve carries it in
  // full, and at rest the push has nothing to correct: no rod error, no speed.
  const double ratio = std::ldexp(1.0, kScoreRatioPowers);
  const ScoreCell exact_rope = run_score_cell(ScoreCase::rope, ratio, exact);
  if (siconos_missing(exact_rope)) CPS_SKIP("Siconos numerics (libsiconos-numerics7): " << exact_rope.why);
  INFO(exact_rope.why);
  REQUIRE(exact_rope.held);
  CHECK(*exact_rope.held);
  CHECK(exact_rope.end_error_m <= kScoreErrorM);
  CHECK(exact_rope.end_speed_mps <= kScoreSpeedMps);
  const ScoreCell paper_rope = run_score_cell(ScoreCase::rope, ratio, paper);
  REQUIRE(paper_rope.held);
  CHECK_FALSE(*paper_rope.held);
  // Two boxes at 2^9: the light cube is squeezed out from under the heavy one with the sweeps;
  // the exact solve keeps the pair.
  const ScoreCell exact_pair = run_score_cell(ScoreCase::two_box, 512.0, exact);
  INFO(exact_pair.why);
  REQUIRE(exact_pair.held);
  CHECK(*exact_pair.held);
  const ScoreCell paper_pair = run_score_cell(ScoreCase::two_box, 512.0, paper);
  REQUIRE(paper_pair.held);
  CHECK_FALSE(*paper_pair.held);
}

TEST_CASE("scorecard: a held case meets the bounds at the end, a failed one says why",
          "[cli][report][scorecard]") {
  // AVBD with its penalties started at 1e6 N/m holds four boxes at 2^9 (penalty >> m / dt^2 of
  // the 512 kg top cube, 1.8e6 N/m, within a few sweeps).
  ScoreRow tuned = row_of("avbd", ScoreSettings::paper);
  tuned.k_start = kTunedAvbdKStart;
  const ScoreCell held = run_score_cell(ScoreCase::four_box, 512.0, tuned);
  INFO(held.why);
  REQUIRE(held.held);
  CHECK(*held.held);
  CHECK(held.why.empty());
  CHECK(held.end_error_m <= kScoreErrorM);
  CHECK(held.end_speed_mps <= kScoreSpeedMps);
  CHECK(held.seconds == Approx(kScoreSeconds));
  // The paper's push at 2^17 on two boxes: the light cube cannot stay under a cube 131,072 times
  // its mass with 25 sweeps; the run stops when it has left and says when.
  const ScoreCell lost = run_score_cell(ScoreCase::two_box, std::ldexp(1.0, 17),
                                        row_of("baumgarte", ScoreSettings::paper));
  REQUIRE(lost.held);
  CHECK_FALSE(*lost.held);
  CHECK_FALSE(lost.why.empty());
}

TEST_CASE("scorecard: held up to counts from 2 and stops at the first ratio that failed",
          "[cli][report][scorecard]") {
  std::vector<ScoreCell> cells(4);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    cells[k].ratio = std::ldexp(1.0, static_cast<int>(k) + 1);
    cells[k].held = true;
  }
  CHECK(held_up_to(cells) == 16.0);
  cells[2].held = false;  // 8 failed: 16 holding again does not count
  CHECK(held_up_to(cells) == 4.0);
  cells[0].held = false;
  CHECK(held_up_to(cells) == 0.0);
  cells[0].held = true;
  cells[1].held.reset();  // not run: it ends the count as a failure would
  CHECK(held_up_to(cells) == 2.0);
}

TEST_CASE("scorecard: each row runs its settings, the source rows their source's world",
          "[cli][report][scorecard]") {
  const WorldDef paper = score_world(ScoreCase::two_box, row_of("soft", ScoreSettings::paper));
  CHECK(paper.push == PushMode::soft);
  CHECK(paper.iterations == 25);
  CHECK(paper.dt == Approx(1.0 / 60.0));
  CHECK(paper.beta == 0.2);
  // Box3D's world, with the cases' own friction.
  const WorldDef box3d = scenes::find_scene("large_pyramid")->world_def();
  const WorldDef soft = score_world(ScoreCase::two_box, row_of("soft", ScoreSettings::source));
  CHECK(soft.iterations == box3d.iterations);
  CHECK(soft.soft_substeps == box3d.soft_substeps);
  CHECK(soft.contact_hertz == box3d.contact_hertz);
  CHECK(soft.warm_start == box3d.warm_start);
  CHECK(soft.friction == paper.friction);
  // The AVBD demo's world.
  const WorldDef demo = scenes::find_scene("avbd_stack")->world_def();
  const WorldDef avbd = score_world(ScoreCase::rope, row_of("avbd", ScoreSettings::source));
  CHECK(avbd.push == PushMode::avbd);
  CHECK(avbd.iterations == demo.iterations);
  CHECK(avbd.avbd_beta == demo.avbd_beta);
  CHECK(avbd.avbd_gamma == demo.avbd_gamma);
  CHECK(avbd.penetration_slop == demo.penetration_slop);
  // Every method has a paper row and a source row; avbd its tuned pair; then the exact solve.
  const std::vector<ScoreRow> rows = score_rows(cps::cli::push_methods());
  CHECK(rows.size() == 2 * cps::cli::push_methods().size() + 3);
  CHECK(rows.back().exact);
  CHECK(rows.back().variant() == "exact solve");
}
