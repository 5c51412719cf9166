// The step context (see step_context.h).
#include "step_context.h"

#include "buffers.h"
#include "integrator.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace cps {

StepContext::StepContext(const StepContext& other)
    : manifolds(detail::copy_with_capacity(other.manifolds)),
      first_points(detail::copy_with_capacity(other.first_points)),
      contact_points(other.contact_points),
      deepest_contact(other.deepest_contact),
      rows(detail::copy_with_capacity(other.rows)),
      layout(other.layout),
      lambda(detail::copy_with_capacity(other.lambda)),
      lambda_second(detail::copy_with_capacity(other.lambda_second)),
      warm_start(other.warm_start ? std::make_unique<WarmStartCache>(*other.warm_start) : nullptr),
      recycler(other.recycler ? std::make_unique<ContactRecycler>(*other.recycler) : nullptr),
      counters(other.counters),
      residual(other.residual),
      time_stages(other.time_stages),
      stage_times(other.stage_times) {}

StepContext::~StepContext() = default;

SolveSettings StepContext::settings(double dt) const {
  return SolveSettings{dt, def->iterations, def->solver, def->friction_model, workers(), def->row_precision};
}

void StepContext::update_workers() {
  if (def->threads <= 1) {
    pool.reset();
  } else if (!pool || pool->count() != def->threads) {
    pool.reset();  // the old threads end before the new ones start
    pool = std::make_unique<Workers>(def->threads);
  }
}

void StepContext::prepare() {
  if (rows.empty()) return;
  if (!solver || solver_assembly != def->assembly) {
    solver = make_constraint_solver(def->assembly);
    solver_assembly = def->assembly;
  }
  StageTimer timer(*this, &StageTimes::prepare);
  const bool coloured = def->solver == SolverKind::coloured_pgs;  // build_rows wrote the spans
  solver->prepare(rows, *bodies, def->solver, def->row_precision, workers(), coloured ? &row_spans : nullptr);
}

void StepContext::solve(const SolveSettings& s, TargetTerms terms, std::vector<double>& out,
                        Eigen::VectorXd& f, const std::vector<double>* start) {
  if (rows.empty()) {
    out.clear();
    f = f_ext;
    return;
  }
  // A later solve without the push is a relax (Sec. 8.1's second solve); every other one a solve.
  StageTimer timer(*this, terms == TargetTerms::bias_only && solves_this_step > 0
                              ? &StageTimes::relax
                              : &StageTimes::solve);
  solver->solve(rows, *bodies, f_ext, terms, s, out, start);
  if (observer || override_solve) [[unlikely]] notify_observer(s, terms, out, start);
  ++solves_this_step;
  ++counters.solves;
  if (def->measure_residual) {
    double max;
    double sum_squares;
    solver->residual(rows, def->friction_model, out, max, sum_squares);
    residual.max = std::max(residual.max, max);
    residual.sum_squares += sum_squares;
    residual.rows += static_cast<std::int64_t>(rows.size());
  }
  // A lambda replaced by override_solve is not the one the solver kept: f from the rows then.
  if (override_solve || !solver->constraint_forces(*bodies, f_ext, f, workers())) {
    add_constraint_forces(rows, out, f_ext, f);
  }
}

void StepContext::notify_observer(const SolveSettings& s, TargetTerms terms,
                                  std::vector<double>& out,
                                  const std::vector<double>* start) const {
  const bool observed =
      observer && (!observe_filter || observe_filter(static_cast<std::int64_t>(counters.steps), solves_this_step,
                                                     static_cast<Eigen::Index>(out.size())));
  if (!observed && !override_solve) return;
  StepSystem system;
  system.step = counters.steps;
  system.solve = solves_this_step;
  system.terms = terms;
  system.dt = s.dt;
  system.solver = s.kind;
  system.iterations = s.iterations;
  system.friction = s.friction;
  RowLimits limits;
  solver->system(system.A, system.b, limits);
  solver->sweep_order(system.order);
  system.c_min = std::move(limits.c_min);
  system.c_max = std::move(limits.c_max);
  system.normal_row = std::move(limits.normal_row);
  system.mu = std::move(limits.mu);
  system.kinds.reserve(rows.size());
  for (const ConstraintRow& row : rows) system.kinds.push_back(row.kind);
  const auto c = static_cast<Eigen::Index>(out.size());
  system.lambda = Eigen::Map<const Eigen::VectorXd>(out.data(), c);
  system.initial = start != nullptr ? Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(start->data(), c))
                                    : Eigen::VectorXd::Zero(c);
  if (observed) observer(system);
  if (!override_solve) return;
  Eigen::VectorXd replaced = system.lambda;
  override_solve(system, replaced);
  if (replaced.size() != c) {
    throw std::invalid_argument("solve override: a lambda of " + std::to_string(replaced.size()) +
                                " entries for a system of " + std::to_string(c) + " rows");
  }
  std::copy(replaced.data(), replaced.data() + c, out.begin());
}

void StepContext::store_warm_start() {
  StageTimer timer(*this, &StageTimes::store);
  if (warm()) warm_start->store(manifolds, rows, distances->size(), lambda, lambda_second, workers(), &first_points);
}

void StepContext::integrate(const Eigen::VectorXd& f_position, const Eigen::VectorXd& f_momentum,
                            double h) {
  StageTimer timer(*this, &StageTimes::integrate);
  cps::integrate(*bodies, f_position, f_momentum, h, def->rotation, workers());
}

}  // namespace cps
