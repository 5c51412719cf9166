// The engine's sweeps and residual on a captured system (see cps/step_system.h).
#include "cps/step_system.h"

#include "solver.h"

#include <stdexcept>
#include <string>

namespace cps {
namespace {

RowLimits limits_of(const StepSystem& s) {
  RowLimits limits;
  limits.c_min = s.c_min;
  limits.c_max = s.c_max;
  limits.normal_row = s.normal_row;
  limits.mu = s.mu;
  return limits;
}

}  // namespace

Eigen::VectorXd solve_sweeps(const StepSystem& s, SolverKind method, int sweeps,
                             const Eigen::VectorXd* start) {
  if (start != nullptr && start->size() != s.rows()) {
    throw std::invalid_argument("solve_sweeps: the start has " + std::to_string(start->size()) +
                                " entries; the system has " + std::to_string(s.rows()) + " rows");
  }
  if (method == SolverKind::coloured_pgs && s.order.empty() && s.rows() > 0) {
    throw std::invalid_argument("solve_sweeps: coloured-pgs on a system captured without its "
                                "sweep order (a solve by " + std::string(name_of(s.solver)) + ")");
  }
  return solve_lcp(s.A, s.b, limits_of(s), s.friction, method, sweeps,
                   start != nullptr ? start->data() : nullptr, &s.order);
}

Eigen::VectorXd natural_map_residual(const StepSystem& s, const Eigen::VectorXd& lambda) {
  return lcp_residual(s.A, s.b, limits_of(s), s.friction, lambda);
}

}  // namespace cps
