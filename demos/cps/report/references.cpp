#include "report/references.h"

#include "criteria.h"
#include "exact_lcp.h"
#include "energy_rise.h"
#include "options/options.h"
#include "report/csv.h"
#include "report/run.h"
#include "report/tasks.h"
#include "report/timing.h"

#include <algorithm>
#include <stdexcept>

namespace cps::cli {
namespace {

bool is_paper_scene(const scenes::Scene& scene) {
  for (const scenes::Scene& s : scenes::paper_scenes()) {
    if (s.name == scene.name) return true;
  }
  return false;
}

}  // namespace

std::vector<SolverErrorPoint> sample_solver_error(const RunSpec& spec, int samples, int& no_solve) {
  const scenes::Scene& scene = spec.scene_def();
  scenes::Run run = make_run_or_usage_error(scene, spec.overrides());
  World& world = run.world;
  const double horizon = spec.horizon_s();
  const auto total = static_cast<std::int64_t>(std::llround(horizon / world.def().dt));
  const std::int64_t every = std::max<std::int64_t>(1, total / std::max(1, samples));
  std::vector<StepSystem> systems;
  world.set_solve_observer([&](const StepSystem& s) {
    if (s.step % every == every - 1) systems.push_back(s);
  });
  no_solve = 0;
  std::int64_t sampled = 0;
  while (scenes::short_of(world, horizon)) {
    const std::size_t before = systems.size();
    const bool sample = world.counters().steps % every == every - 1;
    world.step();
    if (sample) {
      ++sampled;
      if (systems.size() == before) ++no_solve;
    }
    if (!sane_state(world)) break;
  }
  world.set_solve_observer({});
  std::vector<SolverErrorPoint> points;
  for (const StepSystem& s : systems) {
    SolverErrorPoint head;
    head.step = s.step;
    head.t_s = static_cast<double>(s.step) * s.dt;
    head.solve = s.solve;
    head.rows = static_cast<int>(s.rows());
    analysis::ExactSolution exact;
    try {
      exact = analysis::solve_exact(s);
    } catch (const std::exception& e) {
      head.method = "exact";
      head.refused = e.what();
      points.push_back(head);
      continue;
    }
    const auto add = [&](const char* method, int sweeps, const Eigen::VectorXd& lambda) {
      const analysis::Criteria c = analysis::evaluate(s, exact, lambda);
      SolverErrorPoint p = head;
      p.method = method;
      p.sweeps = sweeps;
      p.relative = c.lambda_error_relative;
      p.velocity_mps = c.velocity_error_mps;
      p.residual_N = c.natural_map_N;
      points.push_back(p);
    };
    add("exact", 0, exact.lambda);
    for (const SolverKind method : {SolverKind::pgs, SolverKind::jacobi}) {
      for (const int k : kSolverErrorSweepCounts) {
        add(method == SolverKind::pgs ? "pgs" : "jacobi", k, solve_sweeps(s, method, k));
      }
    }
  }
  return points;
}

double agreement_horizon(const std::vector<double>& t_s, const std::vector<double>& distance_m,
                         double tolerance_m) {
  if (t_s.size() != distance_m.size()) {
    throw std::invalid_argument("agreement_horizon: " + std::to_string(t_s.size()) + " times and " +
                                std::to_string(distance_m.size()) + " distances");
  }
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    if (!(distance_m[i] <= tolerance_m)) return i == 0 ? 0.0 : t_s[i - 1];
  }
  return std::numeric_limits<double>::infinity();
}

ReferenceAgreement compare_references(const RunSpec& spec, double until_s, long max_solves) {
  RunSpec ref = spec;
  ref.solver = SolverKind::pgs;
  ref.iterations = kReferenceIterations;
  ref.substeps = reference_substeps(spec.quick);
  ref.warm_start = 0.0;
  const scenes::Scene& scene = ref.scene_def();
  scenes::Run pgs = make_run_or_usage_error(scene, ref.overrides());
  RunSpec exact_spec = ref;
  exact_spec.iterations = 1;  // the engine's sweeps are replaced by the exact solve
  scenes::Run exact = make_run_or_usage_error(scene, exact_spec.overrides());
  ReferenceAgreement a;
  a.tolerance_m = kAgreementFraction * scenes::largest_body_size(pgs.world);
  std::string refused;
  exact.world.set_solve_override([&](const StepSystem& s, Eigen::VectorXd& lambda) {
    ++a.exact_solves;
    if (!refused.empty()) return;
    try {
      lambda = analysis::solve_exact(s).lambda;
    } catch (const std::exception& e) {
      refused = "the exact solve refused step " + std::to_string(s.step) + " (t = " +
                number(static_cast<double>(s.step) * s.dt) + " s): " + e.what();
    }
  });
  std::vector<double> t_all;
  std::vector<double> d_all;
  const int frame = ref.substeps;  // steps per 1/60 s
  while (scenes::short_of(pgs.world, until_s)) {
    if (a.exact_solves >= max_solves) {
      a.stopped = "the budget of " + std::to_string(max_solves) + " exact solves";
      break;
    }
    pgs.world.step();
    const double start = thread_cpu_seconds();
    exact.world.step();
    a.exact_cpu_s += thread_cpu_seconds() - start;
    if (!refused.empty()) {
      a.stopped = refused;
      break;
    }
    if (!sane_state(pgs.world) || !sane_state(exact.world)) {
      a.stopped = "a reference blew up at " + number(pgs.world.time()) + " s";
      break;
    }
    const double d = scenes::rms_distance(scenes::movable_positions(pgs.world),
                                          scenes::movable_positions(exact.world));
    t_all.push_back(pgs.world.time());
    d_all.push_back(d);
    if (pgs.world.counters().steps % frame == 0 || !scenes::short_of(pgs.world, until_s)) {
      a.t_s.push_back(pgs.world.time());
      a.distance_m.push_back(d);
    }
  }
  exact.world.set_solve_override({});
  a.checked_until_s = pgs.world.time();
  a.horizon_s = agreement_horizon(t_all, d_all, a.tolerance_m);
  return a;
}

ObservedOrder observed_order(double d_coarse, double d_fine) {
  ObservedOrder o;
  if (std::isnan(d_coarse) || std::isnan(d_fine)) return o;
  if (d_coarse == 0.0 && d_fine == 0.0) {  // the three runs agree exactly: no error left
    o.error = 0.0;
    return o;
  }
  if (d_fine == 0.0) {
    o.order = std::numeric_limits<double>::infinity();
    o.error = 0.0;
    return o;
  }
  o.order = std::log2(d_coarse / d_fine);
  if (o.order > 0.0) o.error = d_fine / (std::exp2(o.order) - 1.0);
  return o;
}

double local_order(double e_a, int n_a, double e_b, int n_b) {
  const auto usable = [](double e) { return e > 0.0 && std::isfinite(e); };
  if (!usable(e_a) || !usable(e_b) || !(n_b > n_a) || n_a < 1) return std::nan("");
  return std::log(e_a / e_b) / std::log(static_cast<double>(n_b) / n_a);
}

const ReferenceAgreement* scene_agreement(const scenes::Scene& scene, bool quick) {
  if (scene.report.has_reference_solution || !is_paper_scene(scene)) return nullptr;
  static OnceCache<ReferenceAgreement> cache;
  RunSpec paper{std::string(scene.name)};
  paper.quick = quick;
  return &cache.get(paper.scene + (quick ? " quick" : ""), [&] {
    const double t = std::min(scene.report_trajectory_time_s(), scene.report_horizon_s());
    return compare_references(paper, t, kAgreementSolves);
  });
}

double trajectory_time_of(const scenes::Scene& scene, bool quick) {
  return trajectory_time_with(scene, scene_agreement(scene, quick));
}

double trajectory_time_with(const scenes::Scene& scene, const ReferenceAgreement* a) {
  const double t = std::min(scene.report_trajectory_time_s(), scene.report_horizon_s());
  if (a == nullptr || !(a->horizon_s < t)) return t;
  const double frame = 1.0 / 60.0;
  return std::max(1.0, std::floor(a->horizon_s / frame + 1e-9)) * frame;
}

std::vector<EnergyTrace> energy_traces(const std::string& scene_name, int max_points, bool quick) {
  std::vector<EnergyTrace> traces;
  for (const Choice& push : parameter("push").choices) {
    RunSpec spec{scene_name};
    spec.push = static_cast<PushMode>(push.value);
    const scenes::Scene& scene = spec.scene_def();
    scenes::Run run = make_run_or_usage_error(scene, spec.overrides());
    World& world = run.world;
    const double horizon = scene.report_horizon_s(quick);
    const auto total = static_cast<std::int64_t>(std::llround(horizon / world.def().dt));
    const std::int64_t every = std::max<std::int64_t>(1, (total + max_points - 2) / (max_points - 1));
    EnergyTrace e;
    e.push = std::string(push.name);
    const auto record = [&] {
      const scenes::MechanicalEnergy m = scenes::mechanical_energy(world);
      e.t_s.push_back(world.time());
      e.kinetic_J.push_back(m.kinetic_J);
      e.potential_J.push_back(m.potential_J);
      e.total_J.push_back(m.total_J());
      e.penetration_m.push_back(scenes::deepest_contact(world));
      e.rod_error_m.push_back(scenes::max_rod_error(world));
    };
    record();
    while (scenes::short_of(world, horizon)) {
      try {
        world.step();
      } catch (const std::exception&) {  // a blown-up state the step refuses (too many contacts)
        e.diverged_at_s = world.time();
        break;
      }
      if (!sane_state(world)) {
        e.diverged_at_s = world.time();
        break;
      }
      if (world.counters().steps % every == 0 || !scenes::short_of(world, horizon)) record();
    }
    traces.push_back(std::move(e));
  }
  return traces;
}

}  // namespace cps::cli
