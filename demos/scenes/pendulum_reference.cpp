#include "pendulum_reference.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cps::scenes {
namespace {

struct Rates {
  double theta, phi, theta_acc, phi_acc;
};

Rates derivative(const PinnedBallPendulum& p, const PendulumState& s) {
  const double l = p.rod_length;
  const double r = p.radius;
  const double k = 0.4 * r * r;
  const double g = p.gravity;
  const double d = s.theta - s.phi;
  const double c = std::cos(d);
  const double sn = std::sin(d);
  // M [th'', ph'']^T = rhs, M = [[l^2, l r c], [l r c, r^2 + k]].
  const double m11 = l * l;
  const double m12 = l * r * c;
  const double m22 = r * r + k;
  const double rhs1 = -l * r * s.phi_rate * s.phi_rate * sn - g * l * std::sin(s.theta);
  const double rhs2 = l * r * s.theta_rate * s.theta_rate * sn - g * r * std::sin(s.phi);
  const double det = m11 * m22 - m12 * m12;
  return {s.theta_rate, s.phi_rate, (m22 * rhs1 - m12 * rhs2) / det,
          (m11 * rhs2 - m12 * rhs1) / det};
}

PendulumState advance(const PendulumState& s, const Rates& k, double h) {
  return {s.theta + h * k.theta, s.phi + h * k.phi, s.theta_rate + h * k.theta_acc,
          s.phi_rate + h * k.phi_acc};
}

}  // namespace

double slow_mode_frequency(const PinnedBallPendulum& p) {
  const double l = p.rod_length;
  const double r = p.radius;
  const double k = 0.4 * r * r;
  const double g = p.gravity;
  const double s = r * r + k + r * l;
  // w^2 = g (s - sqrt(s^2 - 4 l k r)) / (2 l k), written to avoid cancellation:
  // w^2 = 2 g r / (s + sqrt(s^2 - 4 l k r)).
  return std::sqrt(2.0 * g * r / (s + std::sqrt(s * s - 4.0 * l * k * r)));
}

double rod_length_for_period(double period, double radius, double gravity) {
  const auto period_of = [&](double l) {
    return 2.0 * M_PI / slow_mode_frequency({l, radius, gravity});
  };
  double lo = 1e-9;
  double hi = 1000.0;
  if (!(period > period_of(lo) && period < period_of(hi))) {
    throw std::invalid_argument("no rod length in (0, 1000] m gives a period of " +
                                std::to_string(period) + " s");
  }
  while (hi - lo > 1e-13) {  // the period grows with the rod length
    const double mid = 0.5 * (lo + hi);
    (period_of(mid) < period ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

PendulumState integrate_rk4(const PinnedBallPendulum& p, PendulumState s, double seconds,
                            double step) {
  const long steps = static_cast<long>(std::ceil(seconds / step - 1e-9));
  const double h = steps > 0 ? seconds / static_cast<double>(steps) : 0.0;
  for (long i = 0; i < steps; ++i) {
    const Rates k1 = derivative(p, s);
    const Rates k2 = derivative(p, advance(s, k1, 0.5 * h));
    const Rates k3 = derivative(p, advance(s, k2, 0.5 * h));
    const Rates k4 = derivative(p, advance(s, k3, h));
    s.theta += h / 6.0 * (k1.theta + 2.0 * k2.theta + 2.0 * k3.theta + k4.theta);
    s.phi += h / 6.0 * (k1.phi + 2.0 * k2.phi + 2.0 * k3.phi + k4.phi);
    s.theta_rate += h / 6.0 * (k1.theta_acc + 2.0 * k2.theta_acc + 2.0 * k3.theta_acc + k4.theta_acc);
    s.phi_rate += h / 6.0 * (k1.phi_acc + 2.0 * k2.phi_acc + 2.0 * k3.phi_acc + k4.phi_acc);
  }
  return s;
}

double centre_angle(const PinnedBallPendulum& p, const PendulumState& s) {
  return std::atan2(p.rod_length * std::sin(s.theta) + p.radius * std::sin(s.phi),
                    p.rod_length * std::cos(s.theta) + p.radius * std::cos(s.phi));
}

std::pair<double, double> centre_angle_and_rate(const PinnedBallPendulum& p, const PendulumState& s) {
  const double x = p.rod_length * std::cos(s.theta) + p.radius * std::cos(s.phi);  // down
  const double y = p.rod_length * std::sin(s.theta) + p.radius * std::sin(s.phi);  // across
  const double x_rate = -p.rod_length * std::sin(s.theta) * s.theta_rate - p.radius * std::sin(s.phi) * s.phi_rate;
  const double y_rate = p.rod_length * std::cos(s.theta) * s.theta_rate + p.radius * std::cos(s.phi) * s.phi_rate;
  return {std::atan2(y, x), (x * y_rate - y * x_rate) / (x * x + y * y)};
}

double swing_phase(double angle, double rate, double w) { return std::atan2(-rate / w, angle); }

}  // namespace cps::scenes
