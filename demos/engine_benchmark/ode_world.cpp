// The ODE copy of a cps world (see engines.h).
#include "engines.h"

#include <ode/ode.h>

#include <array>
#include <stdexcept>

namespace cps::compare {
namespace {

// dInitODE2 once per process, before the first world.
void init_ode_once() {
  static const bool done = [] {
    dInitODE2(0);
    return true;
  }();
  (void)done;
}

class OdeEngine final : public Engine {
 public:
  explicit OdeEngine(const World& cps)
      : dt_(cps.def().dt), friction_(cps.def().friction), restitution_(cps.def().restitution),
        collide_(cps.def().collision) {
    init_ode_once();
    const WorldDef& def = cps.def();
    world_ = dWorldCreate();
    space_ = dHashSpaceCreate(nullptr);
    contacts_ = dJointGroupCreate(0);
    dWorldSetGravity(world_, def.gravity.x(), def.gravity.y(), def.gravity.z());
    dWorldSetQuickStepNumIterations(world_, def.iterations);
    dWorldSetAutoDisableFlag(world_, 0);
    dWorldSetERP(world_, def.beta);  // ODE's default is also 0.2
    for (const Body& b : cps.bodies()) {
      if (b.is_static()) {
        bodies_.push_back(nullptr);
        if (collide_ && b.shape.kind == ShapeKind::plane) {
          const Vec3 n = b.rotation() * b.shape.normal;
          dCreatePlane(space_, n.x(), n.y(), n.z(), n.dot(b.x) + b.shape.offset);
        } else if (b.shape.kind != ShapeKind::plane) {
          throw std::invalid_argument("cps_engine_benchmark: ODE copy supports static planes only");
        }
        continue;
      }
      dBodyID body = dBodyCreate(world_);
      dMass m;
      dGeomID geom = nullptr;
      if (b.shape.kind == ShapeKind::box) {
        const Vec3 e = 2.0 * b.shape.half_extents;
        dMassSetBoxTotal(&m, b.mass, e.x(), e.y(), e.z());
        if (collide_) geom = dCreateBox(space_, e.x(), e.y(), e.z());
      } else {
        dMassSetSphereTotal(&m, b.mass, b.shape.radius);
        if (collide_) geom = dCreateSphere(space_, b.shape.radius);
      }
      dBodySetMass(body, &m);
      dBodySetPosition(body, b.x.x(), b.x.y(), b.x.z());
      const dQuaternion q = {b.o.w(), b.o.x(), b.o.y(), b.o.z()};
      dBodySetQuaternion(body, q);
      const Vec3 v = b.velocity();
      const Vec3 w = b.angular_velocity();
      dBodySetLinearVel(body, v.x(), v.y(), v.z());
      dBodySetAngularVel(body, w.x(), w.y(), w.z());
      if (geom) dGeomSetBody(geom, body);
      bodies_.push_back(body);
    }
    for (const DistanceConstraint& d : cps.distances()) {
      if (d.body_b != kWorldBody) {
        throw std::invalid_argument("cps_engine_benchmark: ODE copy supports distance constraints to a "
                                    "world point only (body_b = " + std::to_string(d.body_b) + ")");
      }
      const Body& a = cps.body(d.body_a);
      const Vec3 p_a = a.x + a.rotation() * d.local_a;
      dJointID j = dJointCreateDBall(world_, nullptr);
      dJointAttach(j, bodies_[static_cast<std::size_t>(d.body_a)], nullptr);
      dJointSetDBallAnchor1(j, p_a.x(), p_a.y(), p_a.z());
      dJointSetDBallAnchor2(j, d.local_b.x(), d.local_b.y(), d.local_b.z());
      dJointSetDBallDistance(j, d.length);
      ++dballs_;
    }
  }

  ~OdeEngine() override {
    dJointGroupDestroy(contacts_);
    dSpaceDestroy(space_);  // destroys its geoms
    dWorldDestroy(world_);  // destroys its bodies and joints
  }

  void step() override {
    contacts_made_ = 0;
    if (collide_) dSpaceCollide(space_, this, &OdeEngine::near_callback);
    dWorldQuickStep(world_, dt_);
    dJointGroupEmpty(contacts_);
    // Rows of this step's quickstep: contact joints (dContactApprox1, one friction coefficient
    // for both directions: 3 rows, or 1 without friction) and the DBall joints (1 row each).
    const double rows = contacts_made_ * (friction_ > 0.0 ? 3.0 : 1.0) + static_cast<double>(dballs_);
    work_.rows += rows;
    work_.row_updates += rows * dWorldGetQuickStepNumIterations(world_);
  }

  int contacts() const override { return contacts_made_; }
  Work work() const override { return work_; }

  std::vector<BodyState> states() const override {
    std::vector<BodyState> out;
    for (dBodyID b : bodies_) {
      BodyState s;
      if (!b) {
        s.is_static = true;
        out.push_back(s);
        continue;
      }
      const dReal* p = dBodyGetPosition(b);
      const dReal* r = dBodyGetRotation(b);  // 3 x 4, row major
      const dReal* v = dBodyGetLinearVel(b);
      s.x = Vec3(p[0], p[1], p[2]);
      for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) s.R(i, k) = r[4 * i + k];
      }
      s.v = Vec3(v[0], v[1], v[2]);
      out.push_back(s);
    }
    return out;
  }

 private:
  static void near_callback(void* data, dGeomID g1, dGeomID g2) {
    auto* self = static_cast<OdeEngine*>(data);
    dBodyID b1 = dGeomGetBody(g1);
    dBodyID b2 = dGeomGetBody(g2);
    if (!b1 && !b2) return;  // two static planes
    constexpr int kMaxContacts = 8;
    std::array<dContactGeom, kMaxContacts> found{};
    const int n = dCollide(g1, g2, kMaxContacts, found.data(), sizeof(dContactGeom));
    self->contacts_made_ += n;
    for (int i = 0; i < n; ++i) {
      dContact c{};
      c.surface.mode = dContactApprox1 | (self->restitution_ > 0.0 ? dContactBounce : 0);
      c.surface.mu = self->friction_;
      c.surface.bounce = self->restitution_;
      c.geom = found[static_cast<std::size_t>(i)];
      dJointID j = dJointCreateContact(self->world_, self->contacts_, &c);
      dJointAttach(j, b1, b2);
    }
  }

  double dt_;
  double friction_;
  double restitution_;
  bool collide_;
  int contacts_made_ = 0;
  int dballs_ = 0;
  Work work_;
  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  std::vector<dBodyID> bodies_;
};

}  // namespace

std::unique_ptr<Engine> make_ode(const World& world) { return std::make_unique<OdeEngine>(world); }

std::string ode_precision() {
  init_ode_once();
  // Asks the library itself (its build), not the header.
  const bool lib_double = dCheckConfiguration("ODE_double_precision") != 0;
  const bool header_double = sizeof(dReal) == sizeof(double);
  if (lib_double != header_double) return "MISMATCH (library and header differ)";
  return lib_double ? "double" : "float";
}

}  // namespace cps::compare
