#pragma once
// The other engines of cps_engine_benchmark: a cps World, once built by a scene, is copied
// into Bullet or ODE (same bodies, shapes, masses, poses, planes, rods, gravity, dt and 25
// solver iterations) so the scenes are the same by construction, then stepped alone.

#include "cps/world.h"

#include <memory>
#include <string>
#include <vector>

namespace cps::compare {

/// What the sanity checks read from any engine: one entry per cps body index (static bodies
/// flagged). x: centre of mass (m, world), R: body to world rotation (3 x 3), v: velocity (m/s).
struct BodyState {
  bool is_static = false;
  Vec3 x = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  Vec3 v = Vec3::Zero();
};

/// One engine's copy of a cps world, stepped by a fixed dt (s) taken from the cps WorldDef.
class Engine {
 public:
  virtual ~Engine() = default;
  /// Advances the copy by one step of dt (s).
  virtual void step() = 0;
  /// The bodies' states, indexed as the cps world's bodies.
  virtual std::vector<BodyState> states() const = 0;
  /// Contact points the last step used (Bullet: points in the dispatcher's persistent
  /// manifolds; ODE: contact joints made).
  virtual int contacts() const = 0;
  /// Solver work summed over every step so far: rows handed to the solver (count) and row
  /// updates (count: each row times the sweeps its solve ran). Bullet: its contact, friction and
  /// joint rows, times the iterations it ran (it stops early when its residual reaches 0;
  /// btSolverAnalyticsData); its split-impulse passes are not counted. ODE: 3 rows a contact
  /// joint with friction (1 without), 1 a DBall joint, times the iterations (quickstep runs them
  /// all).
  struct Work {
    double rows = 0.0;
    double row_updates = 0.0;
  };
  virtual Work work() const = 0;
};

/// Bullet 3.24: btDiscreteDynamicsWorld with btSequentialImpulseConstraintSolver, DBVT
/// broadphase, m_numIterations = def.iterations, deactivation disabled, stepSimulation(dt, 0)
/// (exactly one step of dt per call). Planes: btStaticPlaneShape. Friction: each body gets
/// sqrt(mu) because Bullet multiplies the two bodies' coefficients. A distance constraint to a
/// world point becomes a btPoint2PointConstraint whose pivot is the world point itself, fixed in
/// the ball's frame (a rigid pendulum: 3 rows instead of 1; see README.md). Throws
/// std::invalid_argument for a distance constraint between two bodies (not needed yet).
std::unique_ptr<Engine> make_bullet(const World& world);

/// ODE 0.16: dWorldQuickStep with dWorldSetQuickStepNumIterations(def.iterations), auto-disable
/// off, ERP = beta, hash space; contacts with dContactApprox1 (mu is a coefficient) and no bounce,
/// up to 8 points a pair; planes: dCreatePlane. A distance constraint to a world point becomes
/// a dJointCreateDBall (one row, the same constraint). No geoms at all when def.collision is
/// false. Throws std::invalid_argument for a distance constraint between two bodies.
std::unique_ptr<Engine> make_ode(const World& world);

/// "float" or "double": the btScalar Bullet was compiled with (Debian's headers and pkg-config
/// file must match the library, so the header's choice is the library's).
std::string bullet_precision();
/// Bullet's version as "3.24" (btGetVersion()).
std::string bullet_version();
/// "float" or "double": ODE's dReal (the library's build, checked against the header).
std::string ode_precision();

/// The cps world's own states, for the same sanity checks.
std::vector<BodyState> cps_states(const World& world);

}  // namespace cps::compare
