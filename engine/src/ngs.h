#pragma once
// Non-linear Gauss-Seidel position projection: `--push ngs`. Sources: Box2D v2.4,
// b2ContactSolver::SolvePositionConstraints and b2DistanceJoint::SolvePositionConstraints
// (erincatto/box2d, tag v2.4.1, src/dynamics/b2_contact_solver.cpp, b2_distance_joint.cpp);
// Jolt Physics' position iterations (ContactConstraintManager::SolvePositionConstraints); E.
// Catto, "Modeling and solving constraints", GDC 2009 (the non-linear Gauss-Seidel section).
//
// Derivation. The velocity solve carries no push: A lambda = b (Eq. 6.2.9) with each row's
// target without it (restitution and speculative bias only), and both the positions and the
// stored momenta move with f_c0 = f_ext + J^T lambda (Sec. 3.2). The overlaps and rod errors
// left are then removed from the positions directly, by Gauss-Seidel over the constraints on
// their current, non-linear values (the rows are rebuilt from the moved bodies at every
// correction; the velocities are not touched):
//   contact point: its two witness points move with their bodies (fixed in each body's frame
//     from the point and depth the collision gave at the start of the step; Contact::point is
//     midway, so p_a = point + n d/2 and p_b = point - n d/2); the normal n keeps its world
//     direction (as Jolt's; Box2D 2.4 rotates it with the reference body). Separation
//     s = n . (p_b - p_a) (< 0: overlap), and
//       C = clamp(beta (s + slop), -max_correction, 0)
//     with beta the push factor constant (Box2D's b2_baumgarte, 0.2 like the paper's), slop the
//     penetration slop (WorldDef::penetration_slop; Box2D's b2_linearSlop is 0.005 m) and
//     max_correction (WorldDef::max_correction, m; b2_maxLinearCorrection 0.2 m);
//   rod: u = (p_b - p_a) / |p_b - p_a|, C = clamp(|p_b - p_a| - l, -max_correction,
//     max_correction), corrected in full (Box2D 2.4's distance joint has no factor);
// and for either, with r_a, r_b from the centres of mass to where it acts (for a contact the
// midpoint of the witness points, for both bodies, as Box2D; for a rod its two end points) and
// the axis k (n or u):
//   K = m_a^-1 + m_b^-1 + (r_a x k) . I_a^-1 (r_a x k) + (r_b x k) . I_b^-1 (r_b x k)  (1/kg)
//   P = -C / K k  (kg m)
//   x_a -= m_a^-1 P, o_a turned by -I_a^-1 (r_a x P);  x_b += m_b^-1 P, o_b by +I_b^-1 (r_b x P)
// with I^-1 of the current orientation and the turn as the linear update of Eq. 3.2.4 followed
// by normalisation. Contacts first, then rods, WorldDef::position_iterations times (Box2D 2.4:
// 3; it stops early once every separation is above -3 slop; here the count is fixed, so the
// cost per step does not depend on the state).
//
// Both solvers and both friction models act in the velocity solve (friction has no position
// part); restitution is in its bias; warm starting warm starts it; both assemblies serve it.

#include "cps/body.h"
#include "cps/collision.h"
#include "cps/constraint.h"
#include "cps/parameters.h"

#include <vector>

namespace cps {

/// The position projection's contact points, captured before the integration and projected
/// after it (buffers kept from step to step).
class NgsProjection {
 public:
  /// Records each contact point of `manifolds` that overlaps (depth > 0) as two witness points
  /// fixed in the frames of its bodies (bodies as they are before the integration) and its
  /// normal (unit, a to b). No errors.
  void capture(const std::vector<Manifold>& manifolds, const std::vector<Body>& bodies);

  /// Moves the bodies' positions and orientations (not their momenta) by
  /// def.position_iterations sweeps over the captured contact points and then `distances`
  /// (header comment), with def.beta, def.penetration_slop (m) and def.max_correction (m).
  /// No errors.
  void project(const std::vector<DistanceConstraint>& distances, const WorldDef& def,
               std::vector<Body>& bodies) const;

 private:
  struct Point {
    int body_a = 0;
    int body_b = 0;
    Vec3 local_a = Vec3::Zero();  ///< witness point on a, in a's frame (m)
    Vec3 local_b = Vec3::Zero();  ///< witness point on b, in b's frame (m)
    Vec3 normal = Vec3::UnitY();  ///< world direction from a to b
  };
  std::vector<Point> points_;
};

}  // namespace cps
