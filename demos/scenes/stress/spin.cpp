// spin_100 and spin_1000: a free box (no gravity, no collision) spinning at 100 or 1000 rad/s
// about a non-principal axis. Without torque the integrator never changes l (Eq. 3.2.2 adds
// tau dt = 0), and the orientation is normalised every step, so |l| and |o| are conserved to
// round-off whatever the rotation update; the kinetic energy 1/2 l . I^-1(o) l is exactly
// conserved by the continuous motion but not by the discrete orientation step, which turns the
// box by |w| dt = 1.7 rad (100 rad/s) or 17 rad (1000 rad/s) per step about the axis w of the
// step's start. At these rates that step (linear or exact alike) drives the box within a few
// steps to spin about its axis of least inertia, where w is parallel to l and the energy is the
// largest l allows, |l|^2 / (2 I_min): energy_drift_rel reaches energy_drift_bound_rel.
#include "stress/stress.h"

#include <algorithm>
#include <cmath>

namespace cps::scenes {
namespace {

const Vec3 kHalfExtents(0.1, 0.2, 0.3);  // m
constexpr double kMass = 1.0;            // kg

void populate_spin(World& world, double rate) {
  BodyDef box;
  box.shape = Shape::box(kHalfExtents);
  box.mass = kMass;
  box.position = Vec3(0.0, 1.0, 0.0);
  box.angular_velocity = rate * Vec3(1.0, 1.0, 1.0).normalized();  // not a principal axis
  world.add_body(box);
}

class SpinMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    const Body& b = world.body(0);
    if (!b.l.allFinite() || !b.o.coeffs().allFinite()) {
      nonfinite_ = true;
      return;
    }
    const double energy = 0.5 * b.l.dot(b.angular_velocity());
    if (!l0_) {
      l0_ = b.l;
      e0_ = energy;
      // With l fixed, 1/2 l . R I_body^-1 R^T l lies between |l|^2 / (2 I_max) and
      // |l|^2 / (2 I_min) for every rotation R: the drift can never leave that range.
      const Vec3 inv_i = b.inv_inertia_body.diagonal();  // box: diagonal in body space
      const double l2 = b.l.squaredNorm();
      drift_bound_ = std::max(0.5 * l2 * inv_i.maxCoeff() / e0_ - 1.0, 1.0 - 0.5 * l2 * inv_i.minCoeff() / e0_);
    }
    max_quat_error_ = std::max(max_quat_error_, std::abs(b.o.norm() - 1.0));
    max_l_drift_ = std::max(max_l_drift_, (b.l - *l0_).norm() / l0_->norm());
    max_e_drift_ = std::max(max_e_drift_, std::abs(energy - e0_) / e0_);
    final_e_drift_ = energy / e0_ - 1.0;
  }

  nlohmann::json report() const override {
    return {{"max_quat_norm_error", max_quat_error_},
            {"angular_momentum_drift_rel", max_l_drift_},
            {"energy_drift_rel", max_e_drift_},
            {"final_energy_drift_rel", final_e_drift_},
            {"energy_drift_bound_rel", drift_bound_},
            {"nan", nonfinite_}};
  }

 private:
  std::optional<Vec3> l0_;
  double e0_ = 0.0;
  double max_quat_error_ = 0.0;
  double max_l_drift_ = 0.0;
  double max_e_drift_ = 0.0;
  double final_e_drift_ = 0.0;
  double drift_bound_ = 0.0;
  bool nonfinite_ = false;
};

}  // namespace

WorldDef spin_world_def() {
  WorldDef def = stack_world_def();
  def.gravity = Vec3::Zero();
  def.collision = false;
  def.friction = 0.0;
  return def;
}

void populate_spin_100(World& world) { populate_spin(world, 100.0); }
void populate_spin_1000(World& world) { populate_spin(world, 1000.0); }

std::unique_ptr<Metrics> make_spin_metrics(const World& world) { return observed<SpinMetrics>(world); }

}  // namespace cps::scenes
