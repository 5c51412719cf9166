#include "report/mass_ratio.h"

#include "report/run.h"

#include <string>

namespace cps::cli {
namespace {

// The pair in `world` (made by scenes::populate_mass_ratio: body 1 light, body 2 heavy). Held:
// the light cube is still between the heavy cube and the ground, that is its centre is within
// h of the heavy cube's vertical axis (the heavy cube's centre of mass is over the light cube's
// top face: it rests on it, not beside it) and the heavy cube's centre is within
// kHeldHeightTolerance of its stacked height.
PairOutcome pair_outcome(const World& world) {
  PairOutcome o;
  if (!sane_state(world)) return o;
  const Vec3& light = world.body(1).x;
  const Vec3& heavy = world.body(2).x;
  o.finite = true;
  o.light_offset_m = std::hypot(light.x() - heavy.x(), light.z() - heavy.z());
  o.heavy_height_m = heavy.y();
  o.overlap_m = scenes::max_penetration_now(world);
  o.held = o.light_offset_m <= scenes::kMassRatioHalfEdge &&
           std::abs(o.heavy_height_m - kStackedHeight) <= kHeldHeightTolerance;
  return o;
}

}  // namespace

PairOutcome run_pair(double ratio, SolverKind solver, PushMode push, int iterations,
                     double seconds) {
  WorldDef def = scenes::mass_ratio_world_def();
  def.solver = solver;
  def.push = push;
  def.iterations = iterations;
  World world(def);
  scenes::populate_mass_ratio(world, ratio);
  while (scenes::short_of(world, seconds)) {
    world.step();
    if (!sane_state(world)) return {};
  }
  return pair_outcome(world);
}

std::vector<PairRow> mass_ratio_rows() {
  std::vector<PairRow> rows;
  for (const double ratio : kMassRatios) {
    for (const Choice& c : parameter("push").choices) {
      const auto push = static_cast<PushMode>(c.value);
      for (const SolverKind solver : {SolverKind::pgs, SolverKind::jacobi}) {
        if (solver != SolverKind::pgs && !push_reads(push).solver) continue;  // the same run again
        rows.push_back({ratio, solver, push, {}, {}});
      }
    }
  }
  return rows;
}

std::string pair_id(const PairRow& row) {
  std::string id = "mass_ratio.";
  id.append(number(row.mass_ratio)).append(".").append(name_of(row.solver));
  return id.append(".").append(name_of(row.push));
}

void run_pair_row(PairRow& r) {
  r.outcome = run_pair(r.mass_ratio, r.solver, r.push, kPairTableIterations, kPairSeconds);
  r.iterations_holding.clear();
  for (int n = 1; n <= 256; n *= 2) {
    const PairOutcome q = run_pair(r.mass_ratio, r.solver, r.push, n, kPairSeconds);
    if (q.held && q.overlap_m < kHoldingOverlapM) r.iterations_holding.push_back(n);
  }
}

CsvTable mass_ratio_table(const std::vector<PairRow>& rows) {
  CsvTable table;
  table.columns = {"study", "solver", "push", "iterations", "mass_ratio", "seconds", "held",
                   "heavy_height_m", "light_offset_m", "overlap_m", "iterations_holding"};
  for (const PairRow& r : rows) {
    std::string holding;
    for (const int n : r.iterations_holding) {
      if (!holding.empty()) holding += ' ';
      holding += std::to_string(n);
    }
    table.rows.push_back({pair_id(r), std::string(name_of(r.solver)), std::string(name_of(r.push)),
                          std::to_string(kPairTableIterations), number(r.mass_ratio),
                          number(kPairSeconds), r.outcome.held ? "1" : "0",
                          number(r.outcome.heavy_height_m), number(r.outcome.light_offset_m),
                          number(r.outcome.overlap_m), holding});
  }
  return table;
}

}  // namespace cps::cli
