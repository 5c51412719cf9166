// `cps simulate --solver-error` (see solver_error.h).
#include "commands/solver_error.h"

#include "commands/system_rows.h"
#include "criteria.h"
#include "exact_lcp.h"
#include "options/options.h"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <utility>

namespace cps::cli {

std::vector<std::int64_t> parse_steps(const std::string& at, std::int64_t total_steps,
                                      const std::string& option) {
  if (total_steps < 1) throw UsageError(option + ": the run takes no step");
  if (at.empty()) return {total_steps - 1};
  std::vector<std::int64_t> steps;
  for (const long long s : parse_counts(at, 0, total_steps - 1, option, "a step of this run")) {
    steps.push_back(s);
  }
  return steps;
}

SolverErrorPlan plan_solver_error(const std::string& path, const std::string& at,
                                  const std::string& sweeps, std::int64_t total_steps) {
  SolverErrorPlan plan;
  plan.path = path;
  if (total_steps < 1) throw UsageError("--solver-error: the run takes no step");
  plan.steps = parse_steps(at, total_steps, "--at");
  for (const long long k : parse_counts(sweeps, 0, kMaxSolverErrorSweeps, "--sweeps", "a sweep count")) {
    plan.sweeps.push_back(static_cast<int>(k));
  }
  return plan;
}

std::string solver_error_header() {
  return "step,t_s,solve,rows,method,sweeps," + std::string(analysis::kCriteriaColumns);
}

std::filesystem::path solver_error_rows_path(const std::filesystem::path& path) {
  return path.parent_path() / (path.stem().string() + "-rows.csv");
}

SolverErrorWriter::SolverErrorWriter(SolverErrorPlan plan, const std::string& scene, bool force,
                                     nlohmann::json info)
    : plan_(std::move(plan)), info_(std::move(info)) {
  const std::string file = plan_.path.filename().string();
  const std::string rows_file = solver_error_rows_path(plan_.path).filename().string();
  output_ = plan_output({.folder = plan_.path.parent_path(),
                         .files = {file, rows_file},
                         .command = "simulate",
                         .use = FolderUse::shared,
                         .scenes = {{file, scene}, {rows_file, scene}},
                         .option = "--solver-error",
                         .force = force});
}

void SolverErrorWriter::observe(World& world, double work_left) {
  long long sweeps = 0;
  for (const int k : plan_.sweeps) sweeps += k;
  // PGS, Jacobi and coloured PGS (the last for a coloured run only: counted always).
  constexpr double kSweepingMethods = 3.0;
  world.set_solve_observer(
      [this](const StepSystem& s) { systems_.push_back(s); },
      [this, sweeps, work_left](std::int64_t step, int solve, Eigen::Index rows) {
        if (!std::binary_search(plan_.steps.begin(), plan_.steps.end(), step)) return false;
        const std::string which = "--solver-error: step " + std::to_string(step) + ", solve " +
                                  std::to_string(solve) + " has " + std::to_string(rows) + " rows";
        if (rows > kMaxExactRows) {
          throw UsageError(which + ", more than the " + std::to_string(kMaxExactRows) +
                           " an exact solve takes (a dense LCP solved by Lemke's method); give a "
                           "smaller scene, or --at a step with fewer contacts");
        }
        sweep_work_ += kSweepingMethods * static_cast<double>(sweeps) * static_cast<double>(rows);
        if (sweep_work_ > work_left) {
          throw UsageError(which + ": its re-solves (rows x " + std::to_string(sweeps) +
                           " sweeps of --sweeps x 3 methods) bring them to " + count_text(sweep_work_) +
                           " row-sweeps, more than the " + count_text(std::max(0.0, work_left)) +
                           " that --max-work leaves after the run; give smaller --sweeps, fewer --at "
                           "steps, or a larger --max-work");
        }
        return true;
      });
}

long SolverErrorWriter::finish() {
  begin_output(output_, info_);
  std::string text = solver_error_header() + "\n";
  std::string rows_text = "step,solve," + system_rows_header("") + "\n";
  long rows = 0;
  for (const std::int64_t step : plan_.steps) {
    const bool solved = std::any_of(systems_.begin(), systems_.end(),
                                    [&](const StepSystem& s) { return s.step == step; });
    if (!solved) std::cerr << "solver-error: step " << step << " had no solve (no contact or rod)\n";
  }
  for (const StepSystem& s : systems_) {
    analysis::ExactSolution exact;
    try {
      exact = analysis::solve_exact(s);
    } catch (const std::exception& e) {
      throw std::runtime_error("solver-error: step " + std::to_string(s.step) + ", solve " +
                               std::to_string(s.solve) + ": " + e.what());
    }
    // The least-norm exact solution (fixed friction), or the one found (coupled friction).
    const Eigen::VectorXd exact_lambda =
        s.friction == FrictionModel::fixed ? exact.distance(s, Eigen::VectorXd::Zero(s.rows())).nearest
                                           : exact.lambda;
    rows_text += system_rows(s, std::to_string(s.step) + "," + std::to_string(s.solve) + ",", {},
                             exact_lambda);
    const double t = static_cast<double>(s.step) * s.dt;
    const auto row = [&](const char* method, int sweeps, const Eigen::VectorXd& lambda) {
      char head[128];
      std::snprintf(head, sizeof head, "%lld,%.9g,%d,%lld,%s,%d,", static_cast<long long>(s.step),
                    t, s.solve, static_cast<long long>(s.rows()), method, sweeps);
      text += head + analysis::csv_fields(analysis::evaluate(s, exact, lambda)) + "\n";
      ++rows;
    };
    row("exact", 0, exact.lambda);
    row("engine", s.iterations, s.lambda);
    for (const SolverKind method : {SolverKind::pgs, SolverKind::jacobi, SolverKind::coloured_pgs}) {
      // Coloured PGS sweeps in the order of the engine's coloured solve: a run with it only.
      if (method == SolverKind::coloured_pgs && s.order.empty()) continue;
      const std::string name(name_of(method));
      for (const int k : plan_.sweeps) row(name.c_str(), k, solve_sweeps(s, method, k));
    }
  }
  write_text_atomic(plan_.path, text);
  write_text_atomic(solver_error_rows_path(plan_.path), rows_text);
  end_output(output_, info_);
  return rows;
}

}  // namespace cps::cli
