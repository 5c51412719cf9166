// The two implementations of ConstraintSolver (see constraint_solver.h).
#include "constraint_solver.h"

#include "matrix_free.h"
#include "solver.h"

#include <stdexcept>

namespace cps {
namespace {

// The paper's form (Sec. 6): sparse J (c x 6n), M^-1 (6n x 6n) and A = J M^-1 J^T (c x c) built
// once a step, b (c) for each solve, lambda by solve_lcp over A.
class ExplicitSolver final : public ConstraintSolver {
 public:
  void prepare(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
               SolverKind kind, RowPrecision /*precision*/, Workers* /*workers*/,
               const std::vector<RowSpan>* spans) override {
    inv_inertia_.resize(bodies.size());
    for (std::size_t i = 0; i < bodies.size(); ++i) inv_inertia_[i] = bodies[i].inv_inertia_world();
    system_ = assemble_matrices(rows, bodies);
    order_.clear();
    if (kind == SolverKind::coloured_pgs) {
      // The matrix-free path's runs and colours, so that both sweep the rows in one order.
      if (spans != nullptr) {
        colour_spans(*spans, rows.size(), bodies, MatrixFreeSystem::kMaxRun, colours_);
      } else {
        colour_rows(rows, bodies, MatrixFreeSystem::kMaxRun, colours_);
      }
      cps::sweep_order(colours_, order_);
    }
  }

  void solve(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
             const Eigen::VectorXd& f_ext, TargetTerms terms, const SolveSettings& settings,
             std::vector<double>& lambda, const std::vector<double>* initial) override {
    // v1 from the momenta as they are now, with the inverse inertia of prepare() (the same
    // numbers as system_velocity() when the bodies have not moved since).
    v1_.resize(6 * static_cast<Eigen::Index>(bodies.size()));
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const auto k = 6 * static_cast<Eigen::Index>(i);
      v1_.segment<3>(k) = bodies[i].inv_mass * bodies[i].p;
      v1_.segment<3>(k + 3) = inv_inertia_[i] * bodies[i].l;
    }
    system_.b = assemble_rhs(rows, system_.J, system_.M_inv, v1_, f_ext, settings.dt, terms);
    last_kind_ = settings.kind;
    if (settings.kind == SolverKind::coloured_pgs && order_.size() != rows.size()) {
      throw std::logic_error("explicit solve: coloured-pgs needs a prepare() for it");
    }
    const Eigen::VectorXd x =
        solve_lcp(system_.A, system_.b, system_.limits, settings.friction, settings.kind,
                  settings.iterations, initial != nullptr ? initial->data() : nullptr, &order_);
    lambda.assign(x.data(), x.data() + x.size());
  }

  void residual(const std::vector<ConstraintRow>& /*rows*/, FrictionModel friction,
                const std::vector<double>& lambda, double& max,
                double& sum_squares) const override {
    const Eigen::VectorXd r =
        lcp_residual(system_.A, system_.b, system_.limits, friction,
                     Eigen::Map<const Eigen::VectorXd>(lambda.data(), static_cast<Eigen::Index>(lambda.size())));
    max = r.size() > 0 ? r.maxCoeff() : 0.0;
    sum_squares = r.squaredNorm();
  }

  void system(SparseRowMatrix& A, Eigen::VectorXd& b, RowLimits& limits) const override {
    A = system_.A;
    b = system_.b;
    limits = system_.limits;
  }

  void sweep_order(std::vector<int>& order) const override {
    order.clear();
    if (last_kind_ == SolverKind::coloured_pgs) order = order_;
  }

 private:
  std::vector<Mat3> inv_inertia_;  // n: world inverse inertia per body at prepare()
  RowColours colours_;             // coloured PGS: the rows' runs by colour
  std::vector<int> order_;         // coloured PGS: the rows in sweep order (c); else empty
  SolverKind last_kind_ = SolverKind::pgs;
  Eigen::VectorXd v1_;  // 6n: [v_i, w_i] per body at the solve (m/s, rad/s)
  System system_;
};

// The matrix-free form (matrix_free.h): w = M^-1 J^T lambda per body, O(12) a row update, no
// allocation once its buffers have their working size.
class MatrixFreeSolver final : public ConstraintSolver {
 public:
  void prepare(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
               SolverKind kind, RowPrecision precision, Workers* workers,
               const std::vector<RowSpan>* spans) override {
    cps::prepare(system_, rows, bodies, kind, workers, precision, spans);
  }

  void solve(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
             const Eigen::VectorXd& f_ext, TargetTerms terms, const SolveSettings& settings,
             std::vector<double>& lambda, const std::vector<double>* initial) override {
    rhs(system_, rows, bodies, f_ext, settings.dt, terms, settings.workers);
    last_kind_ = settings.kind;
    cps::solve(system_, rows, settings.friction, settings.kind, settings.iterations, lambda,
               initial, settings.kind == SolverKind::coloured_pgs ? settings.workers : nullptr);
  }

  void residual(const std::vector<ConstraintRow>& rows, FrictionModel friction,
                const std::vector<double>& lambda, double& max,
                double& sum_squares) const override {
    cps::residual(system_, rows, friction, lambda, max, sum_squares);
  }

  void system(SparseRowMatrix& A, Eigen::VectorXd& b, RowLimits& limits) const override {
    cps::explicit_system(system_, A, b, limits);
  }

  void sweep_order(std::vector<int>& order) const override {
    order.clear();
    if (last_kind_ == SolverKind::coloured_pgs) order = system_.perm;
  }

  bool constraint_forces(const std::vector<Body>& bodies, const Eigen::VectorXd& f_ext, Eigen::VectorXd& f,
                         Workers* workers) const override {
    if (last_kind_ != SolverKind::coloured_pgs) return false;
    cps::constraint_forces(system_, bodies, f_ext, f, workers);
    return true;
  }

 private:
  MatrixFreeSystem system_;
  SolverKind last_kind_ = SolverKind::pgs;
};

}  // namespace

std::unique_ptr<ConstraintSolver> make_constraint_solver(Assembly assembly) {
  if (assembly == Assembly::explicit_matrices) return std::make_unique<ExplicitSolver>();
  return std::make_unique<MatrixFreeSolver>();
}

void add_constraint_forces(const std::vector<ConstraintRow>& rows,
                           const std::vector<double>& lambda, const Eigen::VectorXd& f_ext,
                           Eigen::VectorXd& f) {
  f = f_ext;  // same size every step: no allocation
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const ConstraintRow& row = rows[r];
    if (row.body_a != kWorldBody) f.segment<6>(6 * row.body_a) += lambda[r] * row.j.head<6>();
    if (row.body_b != kWorldBody) f.segment<6>(6 * row.body_b) += lambda[r] * row.j.tail<6>();
  }
}

}  // namespace cps
