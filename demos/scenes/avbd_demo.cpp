// The scenes of the AVBD authors' 3D demo (savant117/avbd-demo3d, source/scenes.h: sceneStack,
// sceneStackRatio, scenePyramid, sceneRope, sceneHeavyRope, sceneDynamicFriction,
// sceneStaticFriction), built with the demo's geometry, densities and friction, and the demo's
// solver settings as their own world (source/solver.cpp defaultParams, solver.h): AVBD at dt 1/60
// s, 10 iterations, penalty ramp beta 1e4 N/m^2 (the demo's linear beta: every row here is linear),
// alpha 0.99, gamma 0.999, penalties in [1, 1e10] N/m, no post-stabilisation, g = -10 m/s^2. The
// demo's contacts rest at its collision margin, 0.01 m deep: here the penetration slop. Friction
// mixes as the demo's, sqrt(mu_a mu_b) (pair_friction).
//
// Axes: the demo's z is up; here y is. A demo point (x, y, z) is (x, z - top, -y) here, top the
// height of the top face of the demo's ground box (a 100 m x 100 m x 1 m static box), so that its
// top face is the ground plane y = 0.
#include "avbd_demo.h"

#include <algorithm>
#include <array>
#include <numbers>
#include <vector>

namespace cps::scenes {
namespace {

constexpr double kGroundFriction = 0.5;  // the demo's ground box

// A demo box: full widths (x, y, z of the demo, m), density (kg/m^3), its own friction, demo
// position (m) and velocity (m/s); mass and inertia from the widths and density as the demo's
// Rigid computes them.
void add_demo_box(World& world, Vec3 size, double density, double friction, Vec3 position,
                  double ground_top, Vec3 velocity = Vec3::Zero()) {
  BodyDef box;
  box.shape = Shape::box(0.5 * Vec3(size.x(), size.z(), size.y()));
  box.mass = density * size.x() * size.y() * size.z();
  box.position = Vec3(position.x(), position.z() - ground_top, -position.y());
  box.velocity = Vec3(velocity.x(), velocity.z(), -velocity.y());
  box.friction = friction;
  world.add_body(box);
}

WorldDef avbd_demo_world_def() {
  WorldDef def;
  def.gravity = Vec3(0.0, -10.0, 0.0);
  def.dt = 1.0 / 60.0;
  def.push = PushMode::avbd;
  def.iterations = 10;
  def.avbd_beta = 1.0e4;
  def.avbd_alpha = 0.99;
  def.avbd_gamma = 0.999;
  def.avbd_k_start = 1.0;
  def.avbd_k_max = 1.0e10;
  def.avbd_post_iterations = 0;
  def.penetration_slop = 0.01;
  def.contact_margin = 1e-6;
  def.friction = kGroundFriction;
  def.restitution = 0.0;
  return def;
}

// sceneStack: ten 1 m cubes, 1 kg, dropped from 0.5 m apart.
void populate_demo_stack(World& world) {
  add_ground(world);
  for (int i = 0; i < 10; ++i) {
    add_demo_box(world, Vec3::Ones(), 1.0, 0.5, Vec3(0.0, 0.0, 1.5 * i + 1.0), 0.5);
  }
}

// sceneStackRatio: four cubes of 1, 2, 4 and 8 m at density 1 (1, 8, 64 and 512 kg), each
// resting on the one below as built.
void populate_demo_stack_ratio(World& world) {
  add_ground(world);
  double top = 0.5;
  double s = 1.0;
  for (int i = 0; i < 4; ++i) {
    add_demo_box(world, Vec3::Constant(s), 1.0, 0.5, Vec3(0.0, 0.0, top + 0.5 * s), 0.5);
    top += s;
    s *= 2.0;
  }
}

// scenePyramid: 16 rows of 1 x 0.5 x 0.5 m bricks (0.25 kg), 136 in all, 1 cm apart in a row,
// each row dropped from 0.35 m above the one below.
void populate_demo_pyramid(World& world) {
  constexpr int kSize = 16;
  add_ground(world);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize - y; ++x) {
      add_demo_box(world, Vec3(1.0, 0.5, 0.5), 1.0, 0.5,
                   Vec3(x * 1.01 + y * 0.5 - kSize / 2.0, 0.0, y * 0.85 + 0.5), 0.0);
    }
  }
}

// The demo's Rope and Heavy Rope: link 0 static (the demo's density 0), links 1 x 0.5 x 0.5 m
// (0.25 kg) along x at 1 m, the demo's height 10 m over its ground box centred 20 m down; each
// link joined to the next by a ball joint (the demo's Joint with stiffnessLin infinite,
// stiffnessAng 0) at their touching faces, the joined links not colliding (as the demo's
// constrainedTo). Each joint's feet lie on link i - 1: one 0.25 m in from the centre of its +x
// face, two on that face's edges.
constexpr int kRopeLinks = 20;
constexpr double kRopeGroundTop = -19.5;  // the demo's ground box at z = -20, 1 m thick
constexpr double kRopeArm = 0.25;         // m: the tripod's arm, the links' half width

// Adds link i of the rope (static for i = 0) and returns its index.
int add_rope_link(World& world, int i) {
  BodyDef link;
  link.shape = Shape::box(Vec3(0.5, 0.25, 0.25));
  link.is_static = i == 0;
  link.mass = i == 0 ? 0.0 : 0.25;
  link.position = Vec3(i, 10.0 - kRopeGroundTop, 0.0);
  link.friction = 0.5;
  return world.add_body(link);
}

// The ground and links 0 to count - 1, each joined to the one before; returns the last's index.
int add_rope(World& world, int count) {
  add_ground(world);
  int previous = add_rope_link(world, 0);
  for (int i = 1; i < count; ++i) {
    const int link = add_rope_link(world, i);
    add_ball_joint(world, previous, Vec3(0.5, 0.0, 0.0), link, Vec3(-0.5, 0.0, 0.0), kRopeArm,
                   Vec3(-1.0, 1.0, 1.0));
    previous = link;
  }
  return previous;
}

// sceneRope: 20 links, the first static, hanging out along x and released.
void populate_demo_rope(World& world) { add_rope(world, kRopeLinks); }

// sceneHeavyRope: the rope's first 19 links and, as the 20th, a 5 m cube of 125 kg (500 times a
// link) whose joint point (-2.5, 0, 0) starts 0.5 m from the last link's, as in the demo. The
// cube carries that joint's feet (arm 2.5 m: its centre and two edges of its -x face).
void populate_demo_heavy_rope(World& world) {
  const int previous = add_rope(world, kRopeLinks - 1);
  BodyDef cube;
  cube.shape = Shape::box(Vec3::Constant(2.5));
  cube.mass = 125.0;
  cube.position = Vec3(21.5, 10.0 - kRopeGroundTop, 0.0);
  cube.friction = 0.5;
  const int heavy = world.add_body(cube);
  add_ball_joint(world, heavy, Vec3(-2.5, 0.0, 0.0), previous, Vec3(0.5, 0.0, 0.0), 2.5);
}

// sceneDynamicFriction: eleven 1 x 1 x 0.5 m slabs (0.5 kg) resting on the ground, sent at 10
// m/s along x, with their own friction 5, 4.5, ..., 0 (against the ground's 0.5).
void populate_demo_dynamic_friction(World& world) {
  add_ground(world);
  for (int x = 0; x <= 10; ++x) {
    add_demo_box(world, Vec3(1.0, 1.0, 0.5), 1.0, 5.0 - x / 10.0 * 5.0,
                 Vec3(0.0, -30.0 + 2.0 * x, 0.75), 0.5, Vec3(10.0, 0.0, 0.0));
  }
}

// sceneStaticFriction: a static 40 x 24 x 1 m ramp at 30 degrees (friction 1) with eleven 1 m
// cubes (1 kg) dropped 5 cm onto it, their own friction 0.25, 0.275, ..., 0.5; the pair's mu is
// sqrt(mu 1), so the cubes below mu_box = tan^2 30 deg = 1/3 slide.
void populate_demo_static_friction(World& world) {
  add_ground(world);
  const double angle = 30.0 * std::numbers::pi / 180.0;
  // The demo turns the ramp by 30 degrees about its y; here that is -30 degrees about z.
  const Quat turn(Eigen::AngleAxisd(-angle, Vec3::UnitZ()));
  const Vec3 centre(0.0, 3.0 - 0.5, 0.0);
  BodyDef ramp;
  ramp.shape = Shape::box(Vec3(20.0, 0.5, 12.0));
  ramp.is_static = true;
  ramp.mass = 0.0;
  ramp.position = centre;
  ramp.orientation = turn;
  ramp.friction = 1.0;
  world.add_body(ramp);
  const Vec3 tangent = turn * Vec3::UnitX();
  const Vec3 normal = turn * Vec3::UnitY();
  for (int i = 0; i <= 10; ++i) {
    BodyDef cube;
    cube.shape = Shape::box(Vec3::Constant(0.5));
    cube.mass = 1.0;
    cube.friction = i / 10.0 * 0.25 + 0.25;
    // The demo's y = -10 + 2 i across the ramp is z = 10 - 2 i here.
    cube.position = centre - 12.0 * tangent + Vec3(0.0, 0.0, 10.0 - 2.0 * i) + 1.05 * normal;
    world.add_body(cube);
  }
}

// Each movable body's centre (m) and speed (m/s) at the last observation, in body order; the
// deepest contact of the last step (m); the largest speed (m/s).
class DemoMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    centres_.clear();
    speeds_.clear();
    max_speed_ = 0.0;
    for (const Body& b : world.bodies()) {
      if (b.is_static()) continue;
      centres_.push_back({b.x.x(), b.x.y(), b.x.z()});
      const double v = b.velocity().norm();
      speeds_.push_back(v);
      max_speed_ = std::max(max_speed_, v);
    }
    deepest_ = deepest_contact(world);
  }
  nlohmann::json report() const override {
    nlohmann::json j = nlohmann::json::object();
    j["centres_m"] = centres_;
    j["speeds_mps"] = speeds_;
    j["max_speed_mps"] = max_speed_;
    j["deepest_contact_m"] = deepest_;
    return j;
  }

 private:
  std::vector<std::array<double, 3>> centres_;
  std::vector<double> speeds_;
  double max_speed_ = 0.0;
  double deepest_ = 0.0;
};

std::unique_ptr<Metrics> make_demo_metrics(const World& world) {
  return observed<DemoMetrics>(world);
}

// The gap (m) of each ball joint of a world whose rods are add_ball_joint's triples, in order:
// the distance between the joint's point on the body with the feet, (f_1.x, f_0.y, f_0.z) in
// its frame (f_i the feet), and the point on the other body that the three rods share.
std::vector<double> ball_joint_gaps(const World& world) {
  const auto& rods = world.distances();
  const auto& bodies = world.bodies();
  std::vector<double> gaps;
  for (std::size_t k = 0; k + 2 < rods.size(); k += 3) {
    const DistanceConstraint& r0 = rods[k];
    const DistanceConstraint& r1 = rods[k + 1];
    // The shared point is the same end of all three rods; the feet the other.
    const bool feet_on_b = r0.local_a == r1.local_a && r0.body_a == r1.body_a;
    const int feet_body = feet_on_b ? r0.body_b : r0.body_a;
    const Vec3 f0 = feet_on_b ? r0.local_b : r0.local_a;
    const Vec3 f1 = feet_on_b ? r1.local_b : r1.local_a;
    const int apex_body = feet_on_b ? r0.body_a : r0.body_b;
    const Vec3 apex_local = feet_on_b ? r0.local_a : r0.local_b;
    const Body& fb = bodies[static_cast<std::size_t>(feet_body)];
    const Body& ab = bodies[static_cast<std::size_t>(apex_body)];
    const Vec3 joint = fb.x + fb.rotation() * Vec3(f1.x(), f0.y(), f0.z());
    const Vec3 apex = ab.x + ab.rotation() * apex_local;
    gaps.push_back((apex - joint).norm());
  }
  return gaps;
}

// The demo's measures and each ball joint's gap (m) now, the largest now and the largest over
// the run.
class RopeMetrics final : public Metrics {
 public:
  void observe(const World& world) override {
    demo_.observe(world);
    gaps_ = ball_joint_gaps(world);
    now_ = gaps_.empty() ? 0.0 : *std::max_element(gaps_.begin(), gaps_.end());
    largest_ = std::max(largest_, now_);
  }
  nlohmann::json report() const override {
    nlohmann::json j = demo_.report();
    j["joint_gaps_m"] = gaps_;
    j["max_joint_gap_m"] = now_;
    j["largest_joint_gap_m"] = largest_;
    return j;
  }

 private:
  DemoMetrics demo_;
  std::vector<double> gaps_;
  double now_ = 0.0;      // m: the largest gap now
  double largest_ = 0.0;  // m: the largest gap over the run
};

std::unique_ptr<Metrics> make_rope_metrics(const World& world) {
  return observed<RopeMetrics>(world);
}

constexpr BenchTraits kDemoBench{.start_s = 1.0,
                             .seconds = 1.0,
                             .reason = "from 1 s: the bodies have landed (the demo's scenes at rest or sliding)"};
constexpr BenchTraits kRopeBench{.start_s = 0.0, .seconds = 1.0,
                                 .reason = "the rope swings from the start"};

const std::array kDemoScenes = {
    Scene{.name = "avbd_stack",
          .summary = "the AVBD 3D demo's Stack: ten 1 m cubes dropped 0.5 m apart, with the demo's solver settings",
          .default_seconds = 10.0,
          .world_def = &avbd_demo_world_def,
          .populate = &populate_demo_stack,
          .make_metrics = &make_demo_metrics,
          .camera = CameraPreset{Vec3(12.0, 8.0, 12.0), Vec3(0.0, 6.0, 0.0), 45.0},
          .bench = kDemoBench,
          .report = {}},
    Scene{.name = "avbd_stack_ratio",
          .summary = "the AVBD 3D demo's Stack Ratio: cubes of 1, 2, 4 and 8 m (1 to 512 kg) resting on each other",
          .default_seconds = 10.0,
          .world_def = &avbd_demo_world_def,
          .populate = &populate_demo_stack_ratio,
          .make_metrics = &make_demo_metrics,
          .camera = CameraPreset{Vec3(25.0, 12.0, 25.0), Vec3(0.0, 6.0, 0.0), 45.0},
          .bench = kDemoBench,
          .report = {}},
    Scene{.name = "avbd_pyramid",
          .summary = "the AVBD 3D demo's Pyramid: 136 bricks of 1 x 0.5 x 0.5 m in 16 rows, each row dropped 0.35 m",
          .default_seconds = 10.0,
          .world_def = &avbd_demo_world_def,
          .populate = &populate_demo_pyramid,
          .make_metrics = &make_demo_metrics,
          .camera = std::nullopt,  // framed automatically
          .bench = kDemoBench,
          .report = {}},
    Scene{.name = "avbd_rope",
          .summary = "the AVBD 3D demo's Rope: 20 links of 1 x 0.5 x 0.5 m joined by ball joints, the first fixed, released level",
          .default_seconds = 10.0,
          .world_def = &avbd_demo_world_def,
          .populate = &populate_demo_rope,
          .make_metrics = &make_rope_metrics,
          .camera = CameraPreset{Vec3(0.0, 20.0, 45.0), Vec3(0.0, 20.0, 0.0), 45.0},
          .bench = kRopeBench,
          .report = {}},
    Scene{.name = "avbd_heavy_rope",
          .summary = "the AVBD 3D demo's Heavy Rope: the rope with a 125 kg cube (500 times a link) as its last link",
          .default_seconds = 10.0,
          .world_def = &avbd_demo_world_def,
          .populate = &populate_demo_heavy_rope,
          .make_metrics = &make_rope_metrics,
          .camera = CameraPreset{Vec3(0.0, 20.0, 50.0), Vec3(0.0, 18.0, 0.0), 45.0},
          .bench = kRopeBench,
          .report = {}},
    Scene{.name = "avbd_dynamic_friction",
          .summary = "the AVBD 3D demo's Dynamic Friction: eleven slabs sent at 10 m/s, their friction 5 down to 0",
          .default_seconds = 5.0,
          .world_def = &avbd_demo_world_def,
          .populate = &populate_demo_dynamic_friction,
          .make_metrics = &make_demo_metrics,
          .camera = CameraPreset{Vec3(-10.0, 18.0, 30.0), Vec3(12.0, 0.0, 10.0), 45.0},
          .bench = kDemoBench,
          .report = {}},
    Scene{.name = "avbd_static_friction",
          .summary = "the AVBD 3D demo's Static Friction: eleven cubes on a 30 degree ramp, friction 0.25 to 0.5 against its 1",
          .default_seconds = 5.0,
          .world_def = &avbd_demo_world_def,
          .populate = &populate_demo_static_friction,
          .make_metrics = &make_demo_metrics,
          .camera = std::nullopt,  // framed automatically
          .bench = kDemoBench,
          .report = {}},
};

}  // namespace

std::span<const Scene> avbd_demo_scenes() { return kDemoScenes; }

}  // namespace cps::scenes
