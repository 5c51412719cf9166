// Per-step criteria (see criteria.h).
#include "criteria.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace cps::analysis {

Criteria evaluate(const StepSystem& s, const ExactSolution& exact, const Eigen::VectorXd& lambda) {
  const Eigen::Index c = s.rows();
  if (lambda.size() != c || exact.lambda.size() != c ||
      static_cast<Eigen::Index>(s.kinds.size()) != c) {
    throw std::invalid_argument("evaluate: lambda has " + std::to_string(lambda.size()) +
                                " entries and the exact solution " +
                                std::to_string(exact.lambda.size()) + "; the system has " +
                                std::to_string(c) + " rows and " + std::to_string(s.kinds.size()) +
                                " row kinds");
  }
  Criteria out;
  const auto diverged = [] {
    const double inf = std::numeric_limits<double>::infinity();
    Criteria d{inf, inf, inf, false, inf, inf, inf, inf, inf, inf, inf, true};
    return d;
  };
  if (!lambda.allFinite()) return diverged();
  const ExactSolution::Distance distance = exact.distance(s, lambda);
  out.lambda_error_N = distance.upper_N;
  out.lambda_error_lower_N = distance.lower_N;
  out.lambda_error_exact = distance.exact;
  const double size = exact.smallest_norm_N > 0.0 ? exact.smallest_norm_N : exact.force_scale_N;
  out.lambda_error_relative = out.lambda_error_N / size;
  out.impulse_error_Ns = s.dt * out.lambda_error_N;
  out.velocity_error_mps = s.dt * (s.A * (lambda - exact.lambda)).norm();
  const Eigen::VectorXd w = s.A * lambda - s.b;
  for (Eigen::Index j = 0; j < c; ++j) {
    const RowKind kind = s.kinds[static_cast<std::size_t>(j)];
    if (!(s.A.coeff(j, j) > 0.0)) continue;  // touches no movable body: not solved
    if (kind == RowKind::contact) {
      out.signorini_force_N = std::max(out.signorini_force_N, -lambda[j]);
      out.signorini_velocity_mps = std::max(out.signorini_velocity_mps, -s.dt * w[j]);
      out.complementarity_W = std::max(out.complementarity_W, std::abs(lambda[j] * s.dt * w[j]));
    } else if (kind == RowKind::friction) {
      double lo = s.c_min[j];
      double hi = s.c_max[j];
      const int n = s.normal_row[static_cast<std::size_t>(j)];
      if (s.friction == FrictionModel::coupled && n >= 0) {
        hi = s.mu[j] * std::max(lambda[n], 0.0);
        lo = -hi;
      }
      out.friction_violation_N =
          std::max({out.friction_violation_N, lambda[j] - hi, lo - lambda[j]});
    }
  }
  const Eigen::VectorXd r = natural_map_residual(s, lambda);
  out.natural_map_N = r.size() > 0 ? r.maxCoeff() : 0.0;
  // A finite lambda so large that its products overflow is a diverged sweep all the same.
  for (const double x : {out.lambda_error_N, out.lambda_error_lower_N, out.lambda_error_relative,
                         out.impulse_error_Ns, out.velocity_error_mps, out.signorini_force_N,
                         out.signorini_velocity_mps, out.complementarity_W,
                         out.friction_violation_N, out.natural_map_N}) {
    if (!std::isfinite(x)) return diverged();
  }
  return out;
}

std::string csv_fields(const Criteria& c) {
  char line[640];
  const int n = std::snprintf(
      line, sizeof line, "%.17g,%.17g,%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d",
      c.lambda_error_N, c.lambda_error_lower_N, c.lambda_error_relative, c.lambda_error_exact ? 1 : 0,
      c.impulse_error_Ns, c.velocity_error_mps, c.signorini_force_N, c.signorini_velocity_mps,
      c.complementarity_W, c.friction_violation_N, c.natural_map_N, c.diverged ? 1 : 0);
  return std::string(line, static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(sizeof line) - 1)));
}

}  // namespace cps::analysis
