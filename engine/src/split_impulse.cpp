// Split impulse (see split_impulse.h).
#include "split_impulse.h"

#include "buffers.h"

namespace cps {

void SplitImpulse::solve(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
                         Assembly assembly, const SolveSettings& settings,
                         const Eigen::VectorXd& f_momentum, Eigen::VectorXd& f_position) {
  rows_.clear();
  detail::reserve_with_headroom(rows_, rows.size());
  for (const ConstraintRow& r : rows) {
    if ((r.kind == RowKind::contact && r.push > 0.0) || r.kind == RowKind::distance) {
      rows_.push_back(r);
      rows_.back().normal_row = -1;  // no friction rows here
    }
  }
  if (rows_.empty()) {
    lambda_.clear();
    f_position = f_momentum;
    return;
  }
  if (!solver_ || assembly_ != assembly) {
    solver_ = make_constraint_solver(assembly);
    assembly_ = assembly;
  }
  zero_force_.setZero(f_momentum.size());  // no allocation once it has the size
  solver_->prepare(rows_, bodies);
  SolveSettings pseudo = settings;
  pseudo.softness = nullptr;
  solver_->solve(rows_, bodies, zero_force_, TargetTerms::push_from_rest, pseudo, lambda_, nullptr);
  // f_position = f_momentum + J_p^T lambda_p
  add_constraint_forces(rows_, lambda_, f_momentum, f_position);
}

}  // namespace cps
