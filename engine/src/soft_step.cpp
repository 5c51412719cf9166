// The soft step (see soft_step.h).
#include "soft_step.h"

#include "buffers.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cps {

Softness make_softness(double hertz, double zeta, double h) {
  if (!(hertz > 0.0)) return {};
  const double omega = 2.0 * std::numbers::pi * hertz;
  const double a1 = 2.0 * zeta + h * omega;
  const double a2 = h * omega * a1;
  return {omega / a1, 1.0 / a2};
}

void SoftStep::begin(const std::vector<ConstraintRow>& rows, const std::vector<Manifold>& manifolds,
                     const std::vector<Body>& bodies, const WorldDef& def) {
  h_ = def.dt / static_cast<double>(def.soft_substeps);
  slop_ = def.penetration_slop;
  max_push_ = def.contact_push_max_speed;
  // Box2D: the contact stiffness at most a quarter of the substep rate; twice it for a contact
  // with a static body.
  const double contact_hertz = std::min(def.contact_hertz, 0.25 / h_);
  contact_soft_ = make_softness(contact_hertz, def.contact_damping_ratio, h_);
  static_soft_ = make_softness(2.0 * contact_hertz, def.contact_damping_ratio, h_);
  rod_soft_ = make_softness(def.rod_hertz, def.rod_damping_ratio, h_);
  contacts_.clear();
  std::size_t points = 0;
  for (const Manifold& m : manifolds) points += static_cast<std::size_t>(m.count);
  detail::reserve_with_headroom(contacts_, points);
  for (const Manifold& m : manifolds) {
    const Body& a = bodies[static_cast<std::size_t>(m.body_a)];
    const Body& b = bodies[static_cast<std::size_t>(m.body_b)];
    const Mat3 Ra_t = a.rotation().transpose();
    const Mat3 Rb_t = b.rotation().transpose();
    for (int i = 0; i < m.count; ++i) {
      const Contact& c = m.contacts[static_cast<std::size_t>(i)];
      ContactPoint& p = contacts_.emplace_back();
      p.local_a = Ra_t * (c.point - a.x);
      p.local_b = Rb_t * (c.point - b.x);
      p.normal = c.normal;
      p.depth = c.depth;
      p.touches_static = a.is_static() || b.is_static();
    }
  }
  detail::resize_with_headroom(softness_, rows.size());
}

void SoftStep::set_targets(std::vector<ConstraintRow>& rows,
                           const std::vector<DistanceConstraint>& distances,
                           const std::vector<Body>& bodies, bool soft, bool last) {
  std::size_t contact = 0;
  std::size_t rod = 0;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    ConstraintRow& row = rows[r];
    double gamma = 0.0;
    row.push = 0.0;
    row.bias = 0.0;
    if (row.kind == RowKind::contact) {
      const ContactPoint& p = contacts_[contact++];
      const Body& a = bodies[static_cast<std::size_t>(row.body_a)];
      const Body& b = bodies[static_cast<std::size_t>(row.body_b)];
      // s = -d + n . (p_b - p_a): both points were at the contact point at the start of the step.
      const double s =
          -p.depth + p.normal.dot((b.x + b.rotation() * p.local_b) - (a.x + a.rotation() * p.local_a));
      if (s > 0.0) {
        // Rigid: the points may approach by the gap s within the substep, no further (j . v >=
        // -s / h; Box2D's bias s / h in its sign convention, as a speculative contact here).
        row.bias = -s / h_;
      } else if (soft) {
        const Softness& k = p.touches_static ? static_soft_ : contact_soft_;
        row.push = std::min(k.bias_rate * std::max(-s - slop_, 0.0), max_push_);
        gamma = k.gamma;
      }
      if (!soft && last && row.restitution > 0.0) row.bias = row.restitution;
    } else if (row.kind == RowKind::distance) {
      if (soft) {
        Vec3 pa;
        Vec3 pb;
        distance_endpoints(distances[rod], bodies, pa, pb);
        row.push = -rod_soft_.bias_rate * ((pb - pa).norm() - distances[rod].length);
        gamma = rod_soft_.gamma;
      }
      ++rod;
    }
    softness_[r] = gamma;
  }
}

}  // namespace cps
