// The Bullet copy of a cps world (see engines.h).
#include "engines.h"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <stdexcept>

namespace cps::compare {
namespace {

btVector3 to_bt(const Vec3& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }
Vec3 from_bt(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

// btSequentialImpulseConstraintSolver unchanged, but counting the rows of each solve and the
// iterations it ran (read after the solve from m_analyticsData, which Bullet sets when it
// leaves its iteration loop).
class CountingSolver final : public btSequentialImpulseConstraintSolver {
 public:
  Engine::Work work;

 protected:
  btScalar solveGroupCacheFriendlyIterations(btCollisionObject** bodies, int num_bodies,
                                             btPersistentManifold** manifolds, int num_manifolds,
                                             btTypedConstraint** constraints, int num_constraints,
                                             const btContactSolverInfo& info,
                                             btIDebugDraw* debug) override {
    const int rows = m_tmpSolverContactConstraintPool.size() +
                     m_tmpSolverContactFrictionConstraintPool.size() +
                     m_tmpSolverContactRollingFrictionConstraintPool.size() +
                     m_tmpSolverNonContactConstraintPool.size();
    const int calls = m_analyticsData.m_numSolverCalls;
    const btScalar residual = btSequentialImpulseConstraintSolver::solveGroupCacheFriendlyIterations(
        bodies, num_bodies, manifolds, num_manifolds, constraints, num_constraints, info, debug);
    const int iterations = m_analyticsData.m_numSolverCalls > calls ? m_analyticsData.m_numIterationsUsed : 0;
    work.rows += rows;
    work.row_updates += static_cast<double>(rows) * iterations;
    return residual;
  }
};

class BulletEngine final : public Engine {
 public:
  explicit BulletEngine(const World& cps) : dt_(cps.def().dt) {
    const WorldDef& def = cps.def();
    world_.setGravity(to_bt(def.gravity));
    btContactSolverInfo& info = world_.getSolverInfo();
    info.m_numIterations = def.iterations;
    // Everything else stays at Bullet's defaults (joint ERP 0.2, contact ERP 0.8 with split
    // impulse, warm starting on).
    const btScalar friction = btScalar(std::sqrt(def.friction));  // Bullet: mu = mu_a mu_b
    for (const Body& b : cps.bodies()) {
      btCollisionShape* shape = nullptr;
      switch (b.shape.kind) {
        case ShapeKind::box: shape = new btBoxShape(to_bt(b.shape.half_extents)); break;
        case ShapeKind::sphere: shape = new btSphereShape(btScalar(b.shape.radius)); break;
        case ShapeKind::plane: {
          // cps plane: n . p = n . x + offset (world).
          const Vec3 n = b.rotation() * b.shape.normal;
          shape = new btStaticPlaneShape(to_bt(n), btScalar(n.dot(b.x) + b.shape.offset));
          break;
        }
      }
      shapes_.emplace_back(shape);
      const btScalar mass = b.is_static() ? btScalar(0) : btScalar(b.mass);
      btVector3 inertia(0, 0, 0);
      if (!b.is_static()) shape->calculateLocalInertia(mass, inertia);
      btRigidBody::btRigidBodyConstructionInfo ci(mass, nullptr, shape, inertia);
      if (b.shape.kind != ShapeKind::plane) {
        ci.m_startWorldTransform.setOrigin(to_bt(b.x));
        ci.m_startWorldTransform.setRotation(
            btQuaternion(btScalar(b.o.x()), btScalar(b.o.y()), btScalar(b.o.z()), btScalar(b.o.w())));
      }
      ci.m_friction = friction;
      ci.m_restitution = btScalar(def.restitution);
      auto* body = new btRigidBody(ci);
      body->setLinearVelocity(to_bt(b.velocity()));
      body->setAngularVelocity(to_bt(b.angular_velocity()));
      body->setActivationState(DISABLE_DEACTIVATION);
      bodies_.emplace_back(body);
      if (def.collision) {
        world_.addRigidBody(body);
      } else {
        // In the world (so it moves) but in no collision pair.
        world_.addRigidBody(body, 1, 0);
      }
    }
    for (const DistanceConstraint& d : cps.distances()) {
      if (d.body_b != kWorldBody) {
        throw std::invalid_argument("cps_engine_benchmark: Bullet copy supports distance constraints to a "
                                    "world point only (body_b = " + std::to_string(d.body_b) + ")");
      }
      const Body& a = cps.body(d.body_a);
      // The pivot is the fixed point, expressed in the ball's frame: the ball swings rigidly.
      const Vec3 pivot = a.rotation().transpose() * (d.local_b - a.x);
      auto* c = new btPoint2PointConstraint(*bodies_[static_cast<std::size_t>(d.body_a)], to_bt(pivot));
      constraints_.emplace_back(c);
      world_.addConstraint(c);
    }
  }

  ~BulletEngine() override {
    for (auto& c : constraints_) world_.removeConstraint(c.get());
    for (auto& b : bodies_) world_.removeRigidBody(b.get());
  }

  void step() override { world_.stepSimulation(btScalar(dt_), 0); }

  int contacts() const override {
    int n = 0;
    for (int i = 0; i < dispatcher_.getNumManifolds(); ++i) {
      n += dispatcher_.getManifoldByIndexInternal(i)->getNumContacts();
    }
    return n;
  }

  Work work() const override { return solver_.work; }

  std::vector<BodyState> states() const override {
    std::vector<BodyState> out;
    for (const auto& b : bodies_) {
      BodyState s;
      s.is_static = b->isStaticObject();
      const btTransform& t = b->getCenterOfMassTransform();
      s.x = from_bt(t.getOrigin());
      const btMatrix3x3& m = t.getBasis();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) s.R(r, c) = m[r][c];
      }
      s.v = from_bt(b->getLinearVelocity());
      out.push_back(s);
    }
    return out;
  }

 private:
  double dt_;
  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_{&config_};
  btDbvtBroadphase broadphase_;
  CountingSolver solver_;
  btDiscreteDynamicsWorld world_{&dispatcher_, &broadphase_, &solver_, &config_};
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints_;
};

}  // namespace

std::unique_ptr<Engine> make_bullet(const World& world) { return std::make_unique<BulletEngine>(world); }

std::string bullet_version() {
  const int v = btGetVersion();
  return std::to_string(v / 100) + "." + std::to_string(v % 100);
}

std::string bullet_precision() { return btIsDoublePrecision() ? "double" : "float"; }

}  // namespace cps::compare
