// Augmented Vertex Block Descent: `--push avbd`. Sources: C. Giles, E. Diaz, C. Yuksel,
// "Augmented Vertex Block Descent", ACM TOG 44(4) (SIGGRAPH 2025), Eqs. 2-19; the authors' 2D
// demo savant117/avbd-demo2d (source/solver.cpp Solver::step, manifold.cpp, joint.cpp), read for
// the order of the updates and its defaults, and their 3D demo savant117/avbd-demo3d
// (manifold.cpp: the friction cone and the stick test; solver.cpp: the sweep order); A. Chen, Z.
// Chen, C. Yuksel, "Vertex Block Descent" (2024) for the adaptive warm start. The rods' geometric
// stiffness is derived here.
//
// A primal solver: no A lambda = b is solved (the rows World::step built are not used, so
// `--solver`, `--assembly`, `--friction-model` and `--warm-start` have no effect; they are
// ignored, as ngs ignores the push factor constant). Each step, for every movable body with
// mass m, world inertia I (of the start of the step), start pose (x0, o0):
//   the body's coordinates q = (dx, theta): x = x0 + dx, o = exp(theta) o0 (theta a rotation
//   vector, rad); the inertial target y = (v dt + g dt^2, w dt) (Eq. 2);
//   the initial guess dx = v dt + g a dt^2, theta = w dt, a = clamp((v - v_prev) . g / |g|^2,
//   0, 1) (the adaptive warm start of VBD, as the demo).
// Then `iterations` sweeps of block coordinate descent over the bodies (Gauss-Seidel, the last
// body added first, as the 3D demo's lists), each body solving the 6 x 6 system by LDL^T
// without pivoting, the factorisation of the 2D demo's 3 x 3 body solve (Eqs. 4-6, 13, 17)
//   H dq = -g,  H = M / dt^2 + sum_j k_j J_j J_j^T + G_j,
//               g = M / dt^2 (q - y) + sum_j J_j f_j,  f_j = clamp(k_j C_j + lambda_j, limits)
// with M = diag(m, m, m, I) and J_j the 6-gradient of constraint j for this body; G_j the
// diagonally lumped geometric stiffness |f_j| diag(|column i of d2C_j/dq2|) (Sec. 3.5), nonzero
// for rods only (contacts are linearised, below). The orientation coordinates treat theta as
// additive (the exact derivative of exp(theta) R0 r is dtheta x (R r) only at theta = 0: an
// approximation of order |theta|, the rotation in one step). After each sweep the dual update
// (Eqs. 11, 16): lambda_j = clamp(k_j C_j + lambda_j, limits), and where lambda_j is strictly
// inside its limits, k_j = min(k_j + beta |C_j|, k_max) (a contact's tangent rows: while its
// friction is inside the cone). After the `iterations` sweeps:
// v = dx / dt, w = theta / dt (BDF1), p = m v, l = I(o) w.
//
// Error correction (Eq. 18): C_j = C_j(q) - alpha C_j(q = 0). With post-stabilisation
// (avbd_post_iterations > 0) the sweeps use alpha = 1 (the error at the start is kept), then
// that many more sweeps with alpha = 0 remove it, after the velocities are set: they move the
// positions only (as the demo, which does one); in them only the penalties ramp (k_j += beta |C_j|
// with the full error: not in the demo, which has no dual update there; without it a rod started
// stretched keeps 99 % of its error after 0.5 s, as k stays near k_start). Between steps (Eq. 19): k = clamp(gamma k,
// k_start, k_max), lambda = alpha gamma lambda (lambda kept in full with post-stabilisation); a
// new contact starts at lambda = 0, k = k_start.
//
// Constraints and sign convention (C >= 0 is allowed; a compressive force is negative, as the
// demo's):
//   contact point (collision's normal n from a to b, witness points p_a = point + n d / 2 on a,
//     p_b = point - n d / 2 on b, d the depth; r_a, r_b from the centres of mass at the start):
//     three rows along k in (n, t1, t2) (tangent_basis), linear in q as the demo's:
//       C_k = (1 - alpha) k . (p_b - p_a + slop n) + J_a,k . q_a + J_b,k . q_b,
//       J_a,k = -(k, r_a x k), J_b,k = (k, r_b x k)
//     (penetration_slop in place of the demo's collision margin, so it rests slop deep); the
//     force F = K C + lambda of the three rows, its normal part clamped to F_n <= 0 and its
//     tangential part projected onto the friction cone |F_t| <= mu |F_n| of the same sweep (the
//     3D demo's). Static friction by position (the demo's "stick"): a point whose friction was
//     inside the cone at the last sweep with a tangential error below kStickDistance keeps its
//     witness points in the bodies' frames into the next step (matched by body pair and contact
//     feature), so the tangent rows pull it back.
//   rod (both ends in bodies, or one a world point): C = |p_b - p_a| - l, an equality (no
//     limits), non-linear: with u the unit axis, L = |p_b - p_a|, P = I - u u^T, r = R local,
//       J_b = (u, r_b x u), J_a = -(u, r_a x u),
//       d2C/dq_b2 = A^T (P / L) A + [[0, 0], [0, sym(u r^T) - (u . r) I]], A = [I, -[r]x]
//     (for a: A = [-I, [r]x] and the second block with the opposite sign).
// The step's lambda is written to the contact, friction and rod rows (N, the paper's sign:
// -f) so reports see the forces; lambda_second is cleared.

#include "push_method.h"

#include "../buffers.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>
#include <vector>

namespace cps {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// The 3D demo's STICK_THRESH (m): a point whose tangential error is below it at the end of a
// sweep, its friction inside the cone, keeps its anchors into the next step.
constexpr double kStickDistance = 1e-5;

Mat3 skew(const Vec3& r) {
  Mat3 s;
  s << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
  return s;
}

Quat exp_map(const Vec3& theta) {
  const double angle = theta.norm();
  if (angle < 1e-12) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(angle, theta / angle));
}

// x (6) with H x = g for a symmetric positive definite H (6 x 6): LDL^T without pivoting, as
// the 2D demo solves its bodies' 3 x 3 systems (source/maths.h solve; Golub & Van Loan, Matrix
// Computations, 4th ed., Alg. 4.1.2). A zero pivot gives a non-finite x.
Vec6 solve_ldlt(const Mat6& H, const Vec6& g) {
  Mat6 L;  // strictly lower part: the unit lower factor's entries
  Vec6 d;  // D's diagonal
  for (int i = 0; i < 6; ++i) {
    double pivot = H(i, i);
    for (int k = 0; k < i; ++k) pivot -= L(i, k) * L(i, k) * d[k];
    d[i] = pivot;
    for (int j = i + 1; j < 6; ++j) {
      double e = H(j, i);
      for (int k = 0; k < i; ++k) e -= L(j, k) * L(i, k) * d[k];
      L(j, i) = e / pivot;
    }
  }
  Vec6 x;
  for (int i = 0; i < 6; ++i) {  // L y = g
    double y = g[i];
    for (int k = 0; k < i; ++k) y -= L(i, k) * x[k];
    x[i] = y;
  }
  for (int i = 0; i < 6; ++i) x[i] /= d[i];  // D z = y
  for (int i = 5; i >= 0; --i) {  // L^T x = z
    for (int k = i + 1; k < 6; ++k) x[i] -= L(k, i) * x[k];
  }
  return x;
}

Vec6 axis_gradient(const Vec3& k, const Vec3& r) {
  Vec6 j;
  j << k, r.cross(k);
  return j;
}

struct BodyState {
  Vec3 x0 = Vec3::Zero();
  Quat o0 = Quat::Identity();
  Vec3 dx = Vec3::Zero();     // m
  Vec3 theta = Vec3::Zero();  // rad
  Vec6 y = Vec6::Zero();      // inertial target of (dx, theta)
  Vec6 guess = Vec6::Zero();  // initial guess of (dx, theta)
  Mat3 inertia = Mat3::Zero();  // world inertia at the start (kg m^2)
  Mat3 R = Mat3::Identity();  // current rotation
  double mass = 0.0;          // kg
  bool movable = false;
};

struct ContactState {
  int a = 0;
  int b = 0;
  std::uint32_t feature = 0;
  Vec3 local_a = Vec3::Zero();
  Vec3 local_b = Vec3::Zero();
  std::array<Vec3, 3> axis{};
  std::array<Vec6, 3> Ja{};
  std::array<Vec6, 3> Jb{};
  std::array<double, 3> C0{};
  std::array<double, 3> lambda{};  // N, compressive < 0
  std::array<double, 3> k{};       // N/m
  double mu = 0.0;                 // the pair's friction coefficient (pair_friction)
  bool stick = false;
  auto key() const { return std::tuple(a, b, feature); }
};

struct RodState {
  double lambda = 0.0;  // N
  double k = 0.0;       // N/m
  double C0 = 0.0;      // m
};

class Avbd final : public PushMethod {
 public:
  void step(StepContext& ctx) override {
    const WorldDef& def = *ctx.def;
    std::vector<Body>& bodies = *ctx.bodies;
    const std::vector<DistanceConstraint>& rods = *ctx.distances;
    const double dt = def.dt;
    ctx.lambda_second.clear();
    begin_bodies(def, bodies);
    begin_contacts(def, ctx.manifolds, bodies);
    begin_rods(def, rods);  // C0 at the start poses
    apply_guess();
    build_adjacency(rods);

    const int post = def.avbd_post_iterations;
    const int total = def.iterations + post;
    for (int it = 0; it < total; ++it) {
      const double alpha = post > 0 ? (it < def.iterations ? 1.0 : 0.0) : def.avbd_alpha;
      // The demo's order: its bodies newest first, so the last body added is solved first.
      for (std::size_t i = state_.size(); i-- > 0;) {
        if (state_[i].movable) primal(static_cast<int>(i), alpha, def, rods);
      }
      dual(alpha, def, rods, /*stabilising=*/it >= def.iterations);
      if (it + 1 == def.iterations) set_velocities(bodies, dt);
      if (it >= def.iterations) apply_poses(bodies);
    }
    if (total == def.iterations) apply_poses(bodies);
    write_lambda(ctx);
  }

 private:
  void begin_bodies(const WorldDef& def, const std::vector<Body>& bodies) {
    const double dt = def.dt;
    if (v_prev_.size() != bodies.size()) v_prev_.assign(bodies.size(), Vec3::Zero());
    state_.resize(bodies.size());
    const double g2 = def.gravity.squaredNorm();
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const Body& body = bodies[i];
      BodyState& s = state_[i];
      s.x0 = body.x;
      s.o0 = body.o;
      s.R = body.rotation();
      s.movable = !body.is_static();
      s.mass = body.mass;
      s.dx.setZero();
      s.theta.setZero();
      s.y.setZero();
      if (!s.movable) continue;
      const Vec3 v = body.velocity();
      const Vec3 w = body.angular_velocity();
      s.inertia = s.R * body.inv_inertia_body.inverse() * s.R.transpose();
      s.y << v * dt + def.gravity * dt * dt, w * dt;
      double weight = 0.0;
      if (g2 > 0.0) weight = std::clamp((v - v_prev_[i]).dot(def.gravity) / dt / g2, 0.0, 1.0);
      if (!std::isfinite(weight)) weight = 0.0;
      v_prev_[i] = v;
      s.guess << v * dt + def.gravity * (weight * dt * dt), w * dt;
    }
  }

  // Moves the bodies to the initial guess of begin_bodies (after the rods' C0 is taken at the
  // start poses).
  void apply_guess() {
    for (BodyState& s : state_) {
      if (!s.movable) continue;
      s.dx = s.guess.head<3>();
      s.theta = s.guess.tail<3>();
      s.R = (exp_map(s.theta) * s.o0).toRotationMatrix();
    }
  }

  void begin_contacts(const WorldDef& def, const std::vector<Manifold>& manifolds,
                      const std::vector<Body>& bodies) {
    old_.swap(contacts_);
    std::sort(old_.begin(), old_.end(),
              [](const ContactState& l, const ContactState& r) { return l.key() < r.key(); });
    contacts_.clear();
    detail::reserve_with_headroom(contacts_, contact_point_count(manifolds));
    const bool post = def.avbd_post_iterations > 0;
    for_each_contact_point(manifolds, bodies, [&](const Manifold& m, const Contact& c,
                                                  const Body& a, const Body& b, const Mat3& Ra_t,
                                                  const Mat3& Rb_t) {
      ContactState& s = contacts_.emplace_back();
      s.a = m.body_a;
      s.b = m.body_b;
      s.feature = c.feature;
      s.mu = pair_friction(def.friction, a.friction, b.friction);
      s.local_a = Ra_t * (c.point + 0.5 * c.depth * c.normal - a.x);
      s.local_b = Rb_t * (point_on_b(m, c) - 0.5 * c.depth * c.normal - b.x);
      s.lambda = {0.0, 0.0, 0.0};
      s.k = {0.0, 0.0, 0.0};
      const auto found = std::lower_bound(
          old_.begin(), old_.end(), s.key(),
          [](const ContactState& l, const auto& key) { return l.key() < key; });
      if (found != old_.end() && found->key() == s.key()) {
        s.lambda = found->lambda;
        s.k = found->k;
        s.stick = found->stick;
        if (s.stick) {
          s.local_a = found->local_a;
          s.local_b = found->local_b;
        }
      }
      s.axis[0] = c.normal;
      tangent_basis(c.normal, s.axis[1], s.axis[2]);
      const Vec3 r_a = a.rotation() * s.local_a;
      const Vec3 r_b = b.rotation() * s.local_b;
      const Vec3 gap = (b.x + r_b) - (a.x + r_a) + def.penetration_slop * c.normal;
      for (int r = 0; r < 3; ++r) {
        s.Ja[r] = -axis_gradient(s.axis[r], r_a);
        s.Jb[r] = axis_gradient(s.axis[r], r_b);
        s.C0[r] = s.axis[r].dot(gap);
        if (!post) s.lambda[r] *= def.avbd_alpha * def.avbd_gamma;
        s.k[r] = std::clamp(s.k[r] * def.avbd_gamma, def.avbd_k_start, def.avbd_k_max);
      }
    });
  }

  void begin_rods(const WorldDef& def, const std::vector<DistanceConstraint>& rods) {
    if (rod_.size() != rods.size()) rod_.assign(rods.size(), RodState{});
    for (std::size_t i = 0; i < rods.size(); ++i) {
      RodState& r = rod_[i];
      if (def.avbd_post_iterations == 0) r.lambda *= def.avbd_alpha * def.avbd_gamma;
      r.k = std::clamp(r.k * def.avbd_gamma, def.avbd_k_start, def.avbd_k_max);
      r.C0 = rod_value(rods[i], nullptr, nullptr, nullptr);
    }
  }

  // Each body's constraints: contacts as their index, rods as -(index + 1).
  void build_adjacency(const std::vector<DistanceConstraint>& rods) {
    const std::size_t n = state_.size();
    offset_.assign(n + 1, 0);
    const auto count = [&](int body) {
      if (body >= 0) ++offset_[static_cast<std::size_t>(body) + 1];
    };
    for (const ContactState& c : contacts_) { count(c.a); count(c.b); }
    for (const DistanceConstraint& d : rods) { count(d.body_a); count(d.body_b); }
    for (std::size_t i = 0; i < n; ++i) offset_[i + 1] += offset_[i];
    entries_.resize(static_cast<std::size_t>(offset_[n]));
    fill_ = offset_;
    const auto put = [&](int body, int entry) {
      if (body >= 0) entries_[static_cast<std::size_t>(fill_[static_cast<std::size_t>(body)]++)] = entry;
    };
    for (std::size_t i = 0; i < contacts_.size(); ++i) {
      put(contacts_[i].a, static_cast<int>(i));
      put(contacts_[i].b, static_cast<int>(i));
    }
    for (std::size_t i = 0; i < rods.size(); ++i) {
      put(rods[i].body_a, -static_cast<int>(i) - 1);
      put(rods[i].body_b, -static_cast<int>(i) - 1);
    }
  }

  Vec6 q(int body) const {
    Vec6 v = Vec6::Zero();
    if (body >= 0) {
      const BodyState& s = state_[static_cast<std::size_t>(body)];
      v << s.dx, s.theta;
    }
    return v;
  }

  double contact_value(const ContactState& c, int r, double alpha) const {
    return (1.0 - alpha) * c.C0[static_cast<std::size_t>(r)] + c.Ja[static_cast<std::size_t>(r)].dot(q(c.a)) +
           c.Jb[static_cast<std::size_t>(r)].dot(q(c.b));
  }

  // A contact's force along (n, t1, t2) (N) and what the dual update needs: F = K C + lambda, the
  // normal part clamped to F_n <= 0 and the tangential part projected onto the friction cone
  // |F_t| <= mu |F_n| (the 3D demo's manifold.cpp updatePrimal and updateDual).
  struct ContactForce {
    Vec3 force = Vec3::Zero();
    Vec3 C = Vec3::Zero();      // m: the rows' errors
    bool in_cone = false;       // |F_t| <= mu |F_n| before the projection
  };
  ContactForce contact_force(const ContactState& c, double alpha) const {
    ContactForce out;
    for (int r = 0; r < 3; ++r) {
      const std::size_t ru = static_cast<std::size_t>(r);
      out.C[r] = contact_value(c, r, alpha);
      out.force[r] = c.k[ru] * out.C[r] + c.lambda[ru];
    }
    out.force[0] = std::min(out.force[0], 0.0);
    const double bound = c.mu * std::abs(out.force[0]);
    const double tangential = std::hypot(out.force[1], out.force[2]);
    out.in_cone = tangential <= bound;
    if (!out.in_cone && tangential > 0.0) {
      out.force[1] *= bound / tangential;
      out.force[2] *= bound / tangential;
    }
    return out;
  }

  // The current length error of rod d (m); with `for_body` and outputs, this body's gradient J
  // and the diagonal of the lumped geometric stiffness per unit force (column norms of d2C/dq2).
  double rod_value(const DistanceConstraint& d, const int* for_body, Vec6* J, Vec6* lump) const {
    const auto end = [&](int body, const Vec3& local, Vec3& r) {
      if (body < 0) {
        r.setZero();
        return Vec3(local);
      }
      const BodyState& s = state_[static_cast<std::size_t>(body)];
      r = s.R * local;
      return Vec3(s.x0 + s.dx + r);
    };
    Vec3 r_a;
    Vec3 r_b;
    const Vec3 pa = end(d.body_a, d.local_a, r_a);
    const Vec3 pb = end(d.body_b, d.local_b, r_b);
    const Vec3 ab = pb - pa;
    const double L = ab.norm();
    if (for_body != nullptr) {
      J->setZero();
      lump->setZero();
      if (L > 1e-12) {
        const Vec3 u = ab / L;
        const bool is_b = *for_body == d.body_b;
        const double sign = is_b ? 1.0 : -1.0;
        const Vec3& r = is_b ? r_b : r_a;
        *J << sign * u, sign * r.cross(u);
        Eigen::Matrix<double, 3, 6> A;
        A << sign * Mat3::Identity(), -sign * skew(r);
        Mat6 H = A.transpose() * ((Mat3::Identity() - u * u.transpose()) / L) * A;
        H.bottomRightCorner<3, 3>() +=
            sign * (0.5 * (u * r.transpose() + r * u.transpose()) - u.dot(r) * Mat3::Identity());
        for (int i = 0; i < 6; ++i) (*lump)[i] = H.col(i).norm();
      }
    }
    return L - d.length;
  }

  void primal(int body, double alpha, const WorldDef& def,
              const std::vector<DistanceConstraint>& rods) {
    BodyState& s = state_[static_cast<std::size_t>(body)];
    const double inv_dt2 = 1.0 / (def.dt * def.dt);
    Mat6 H = Mat6::Zero();
    H.topLeftCorner<3, 3>() = s.mass * inv_dt2 * Mat3::Identity();
    H.bottomRightCorner<3, 3>() = s.inertia * inv_dt2;
    Vec6 g = H * (q(body) - s.y);
    for (int e = offset_[static_cast<std::size_t>(body)]; e < offset_[static_cast<std::size_t>(body) + 1]; ++e) {
      const int entry = entries_[static_cast<std::size_t>(e)];
      if (entry >= 0) {
        const ContactState& c = contacts_[static_cast<std::size_t>(entry)];
        const Vec3 f = contact_force(c, alpha).force;
        for (std::size_t r = 0; r < 3; ++r) {
          const Vec6& J = c.a == body ? c.Ja[r] : c.Jb[r];
          g += J * f[static_cast<Eigen::Index>(r)];
          H += c.k[r] * J * J.transpose();
        }
      } else {
        const std::size_t i = static_cast<std::size_t>(-entry - 1);
        Vec6 J;
        Vec6 lump;
        const double C = rod_value(rods[i], &body, &J, &lump) - alpha * rod_[i].C0;
        const double f = rod_[i].k * C + rod_[i].lambda;
        g += J * f;
        H += rod_[i].k * J * J.transpose();
        H.diagonal() += std::abs(f) * lump;
      }
    }
    const Vec6 step = solve_ldlt(H, g);
    if (!step.allFinite()) return;
    s.dx -= step.head<3>();
    s.theta -= step.tail<3>();
    s.R = (exp_map(s.theta) * s.o0).toRotationMatrix();
  }

  // The dual update; while stabilising only the penalties ramp (lambda of the alpha = 0 sweeps
  // would carry the correction into the next step's forces), so a start error that the
  // stabilisation corrects stiffens its row for the next step.
  void dual(double alpha, const WorldDef& def, const std::vector<DistanceConstraint>& rods,
            bool stabilising) {
    const auto ramp = [&](double& k, double C) {
      k = std::min(k + def.avbd_beta * std::abs(C), def.avbd_k_max);
    };
    for (ContactState& c : contacts_) {
      const ContactForce f = contact_force(c, alpha);
      if (f.force[0] < 0.0) ramp(c.k[0], f.C[0]);
      if (f.in_cone) {
        ramp(c.k[1], f.C[1]);
        ramp(c.k[2], f.C[2]);
        if (!stabilising) c.stick = std::hypot(f.C[1], f.C[2]) < kStickDistance;
      }
      if (!stabilising) {
        for (int r = 0; r < 3; ++r) c.lambda[static_cast<std::size_t>(r)] = f.force[r];
      }
    }
    for (std::size_t i = 0; i < rods.size(); ++i) {
      const double C = rod_value(rods[i], nullptr, nullptr, nullptr) - alpha * rod_[i].C0;
      if (!stabilising) rod_[i].lambda += rod_[i].k * C;
      ramp(rod_[i].k, C);
    }
  }

  void set_velocities(std::vector<Body>& bodies, double dt) {
    apply_poses(bodies);
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (!state_[i].movable) continue;
      Body& body = bodies[i];
      body.p = body.mass * state_[i].dx / dt;
      const Mat3 R = state_[i].R;
      body.l = R * body.inv_inertia_body.inverse() * R.transpose() * (state_[i].theta / dt);
    }
  }

  void apply_poses(std::vector<Body>& bodies) const {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const BodyState& s = state_[i];
      if (!s.movable) continue;
      bodies[i].x = s.x0 + s.dx;
      bodies[i].o = (exp_map(s.theta) * s.o0).normalized();
    }
  }

  // ctx.lambda per row (N, the paper's sign, -f) at the rows' places (ctx.layout): each contact
  // point's contact row and, with friction, its two friction rows; each rod's row.
  void write_lambda(StepContext& ctx) const {
    const RowLayout& layout = ctx.layout;
    ctx.lambda.assign(ctx.rows.size(), 0.0);
    for (std::size_t i = 0; i < contacts_.size(); ++i) {
      ctx.lambda[i] = -contacts_[i].lambda[0];
      if (layout.friction) {
        ctx.lambda[layout.friction_row(i)] = -contacts_[i].lambda[1];
        ctx.lambda[layout.friction_row(i) + 1] = -contacts_[i].lambda[2];
      }
    }
    for (std::size_t r = 0; r < rod_.size(); ++r) ctx.lambda[layout.rod_row(r)] = -rod_[r].lambda;
  }

  std::vector<BodyState> state_;
  std::vector<Vec3> v_prev_;
  std::vector<ContactState> contacts_;
  std::vector<ContactState> old_;
  std::vector<RodState> rod_;
  std::vector<int> offset_;
  std::vector<int> fill_;
  std::vector<int> entries_;
};

}  // namespace

std::unique_ptr<PushMethod> make_avbd() { return std::make_unique<Avbd>(); }

}  // namespace cps
