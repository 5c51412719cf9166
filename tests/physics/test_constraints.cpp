// Distance constraints (Sec. 5.2), restitution (Sec. 8.2), friction (Sec. 5.4), the solver and
// rotation alternatives, checked against analytic results.
#include "cps/world.h"
#include "scene.h"
#include "solver.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

using namespace cps;

namespace {

constexpr double kPi = std::numbers::pi;

// A 1 kg ball of radius r on a rod from its centre to a fixed point.
World ball_on_rod(const WorldDef& def, const Vec3& anchor, const Vec3& ball, double length,
                  double r = 0.1) {
  World world(def);
  BodyDef b;
  b.shape = Shape::sphere(r);
  b.mass = 1.0;
  b.position = ball;
  world.add_body(b);
  world.add_distance({0, Vec3::Zero(), kWorldBody, anchor, length});
  return world;
}

double rod_length_now(const World& world) {
  Vec3 a;
  Vec3 b;
  distance_endpoints(world.distances()[0], world.bodies(), a, b);
  return (b - a).norm();
}

}  // namespace

TEST_CASE("a stretched rod shrinks and a compressed rod grows", "[constraint][distance]") {
  WorldDef def;
  def.gravity = Vec3::Zero();
  def.collision = false;
  for (const double start : {1.2, 0.8}) {
    World world = ball_on_rod(def, Vec3::Zero(), Vec3(start, 0, 0), 1.0);
    world.step();
    // One step moves the end by beta (|p_ab| - l) towards the length (docs/conventions.md, Sec. 3).
    const double expected = start - def.beta * (start - 1.0);
    CHECK(rod_length_now(world) == Approx(expected).epsilon(1e-9));
    for (int k = 0; k < 120; ++k) world.step();
    CHECK(std::abs(rod_length_now(world) - 1.0) < 1e-6);
  }
}

TEST_CASE("a small-swing pendulum on a rod keeps its analytic period", "[constraint][distance]") {
  // Rod from the ball's centre: a simple pendulum, T = 2 pi sqrt(L / g) (1 + theta0^2 / 16).
  WorldDef def;
  def.dt = 1.0 / 600.0;
  def.collision = false;
  const double L = 1.0;
  const double theta0 = 3.0 * kPi / 180.0;
  World world = ball_on_rod(def, Vec3(0, 2, 0),
                            Vec3(0, 2, 0) + L * Vec3(std::sin(theta0), -std::cos(theta0), 0), L);
  const double expected = 2.0 * kPi * std::sqrt(L / 10.0) * (1.0 + theta0 * theta0 / 16.0);
  // Times at which x crosses zero going the same way: one period apart.
  std::vector<double> crossings;
  double previous = world.body(0).x.x();
  while (crossings.size() < 6 && world.time() < 20.0) {
    world.step();
    const double x = world.body(0).x.x();
    if (previous > 0.0 && x <= 0.0) {
      crossings.push_back(world.time() - def.dt * x / (x - previous));  // linear interpolation
    }
    previous = x;
  }
  REQUIRE(crossings.size() == 6);
  const double period = (crossings.back() - crossings.front()) / 5.0;
  CHECK(period == Approx(expected).epsilon(0.01));
}

TEST_CASE("restitution: a ball bounces to eps^2 of its drop height", "[constraint][restitution]") {
  // With the single frame push factor the rebound speed is eps times the impact speed, so the
  // ball climbs to eps^2 of its drop height. With Baumgarte the push factor beta d / dt adds to
  // it (Sec. 8.1, Fig. 5): the ball is detected at most v dt deep, so the rebound speed lies
  // between eps v and (eps + beta) v, and the height between eps^2 h and (eps + beta)^2 h.
  for (const PushMode push : {PushMode::baumgarte, PushMode::split}) {
    WorldDef def;
    def.restitution = 0.5;
    def.friction = 0.0;
    def.dt = 1.0 / 600.0;
    def.push = push;
    World world(def);
    world.add_body({Shape::plane(Vec3::UnitY(), 0.0), true});
    BodyDef ball;
    ball.shape = Shape::sphere(0.5);
    ball.position = Vec3(0, 0.5 + 4.0, 0);  // 4 m above the ground
    world.add_body(ball);
    bool bounced = false;
    double apex = 0.0;
    while (world.time() < 3.0) {
      world.step();
      const double v = world.body(1).velocity().y();
      if (v > 0.0) bounced = true;
      if (bounced) apex = std::max(apex, world.body(1).x.y() - 0.5);
      if (bounced && v < 0.0) break;
    }
    INFO("push " << (push == PushMode::split ? "split" : "baumgarte"));
    if (push == PushMode::split) {
      CHECK(apex == Approx(0.25 * 4.0).epsilon(0.05));
    } else {
      CHECK(apex >= 0.95 * 0.25 * 4.0);
      CHECK(apex <= 1.05 * (0.5 + def.beta) * (0.5 + def.beta) * 4.0);
    }
  }
}

TEST_CASE("restitution: a ball resting on the ground does not bounce", "[constraint][restitution]") {
  WorldDef def;
  def.restitution = 0.5;
  World world(def);
  world.add_body({Shape::plane(Vec3::UnitY(), 0.0), true});
  BodyDef ball;
  ball.shape = Shape::sphere(0.5);
  ball.position = Vec3(0, 0.5, 0);
  world.add_body(ball);
  double highest = 0.0;
  for (int k = 0; k < 300; ++k) {
    world.step();
    highest = std::max(highest, world.body(1).x.y());
  }
  // Gravity moves it g dt^2 = 2.8 mm per step at most; a bounce would lift it far more.
  CHECK(highest < 0.5 + 1e-3);
}

TEST_CASE("friction: a box stays on a gentle slope and slides down a steep one",
          "[constraint][friction]") {
  const double mu = 0.5;  // atan(mu) = 26.6 degrees
  for (const FrictionModel model : {FrictionModel::fixed, FrictionModel::coupled}) {
    for (const double degrees : {20.0, 35.0}) {
      const double theta = degrees * kPi / 180.0;
      const Vec3 n(-std::sin(theta), std::cos(theta), 0.0);  // slope falls towards +x
      const Vec3 down_slope(std::cos(theta), std::sin(theta), 0.0);
      WorldDef def;
      def.friction = mu;
      def.friction_model = model;
      def.dt = 1.0 / 240.0;
      World world(def);
      world.add_body({Shape::plane(n, 0.0), true});
      BodyDef box;
      box.shape = Shape::box(Vec3::Constant(0.5));
      box.position = 0.5 * n;
      box.orientation = Quat(Eigen::AngleAxisd(theta, Vec3::UnitZ()));
      world.add_body(box);
      for (int k = 0; k < 60; ++k) world.step();  // settle
      const Vec3 x0 = world.body(1).x;
      const double v0 = world.body(1).velocity().dot(-down_slope);
      const double t = 1.0;
      for (int k = 0; k < 240; ++k) world.step();
      const double travelled = (world.body(1).x - x0).dot(-down_slope);
      INFO(degrees << " degrees, model " << (model == FrictionModel::fixed ? "fixed" : "coupled"));
      if (degrees < 26.0) {
        CHECK(std::abs(travelled) < 1e-3);
      } else {
        const double a = 10.0 * (std::sin(theta) - mu * std::cos(theta));
        CHECK(travelled == Approx(v0 * t + 0.5 * a * t * t).epsilon(0.05));
      }
    }
  }
}

TEST_CASE("Jacobi and PGS agree on a diagonally dominant system", "[solver]") {
  Eigen::MatrixXd A(3, 3);
  A << 4, 1, 0.5, 1, 5, 1, 0.5, 1, 3;
  const Eigen::VectorXd b = Eigen::Vector3d(1, -2, 3);
  RowLimits limits;
  limits.c_min = Eigen::VectorXd::Constant(3, -kInfinity);
  limits.c_max = Eigen::VectorXd::Constant(3, kInfinity);
  const SparseRowMatrix As = A.sparseView();
  const Eigen::VectorXd exact = A.ldlt().solve(b);
  const Eigen::VectorXd jacobi = solve_lcp(As, b, limits, FrictionModel::fixed, SolverKind::jacobi, 200);
  CHECK((jacobi - exact).norm() < 1e-10);
  // After one sweep they differ: Jacobi does not use the new values within the sweep.
  const Eigen::VectorXd j1 = solve_lcp(As, b, limits, FrictionModel::fixed, SolverKind::jacobi, 1);
  const Eigen::VectorXd p1 = solve_lcp(As, b, limits, FrictionModel::fixed, SolverKind::pgs, 1);
  CHECK(j1[0] == Approx(p1[0]));
  CHECK(std::abs(j1[1] - p1[1]) > 1e-3);
  CHECK(j1[1] == Approx(b[1] / A(1, 1)));
}

TEST_CASE("the exact rotation update turns by |w| dt per step", "[integrator]") {
  WorldDef def;
  def.gravity = Vec3::Zero();
  def.rotation = RotationUpdate::exact;
  World world(def);
  BodyDef box;
  box.shape = Shape::box(Vec3(0.5, 1.0, 1.5));
  box.angular_velocity = Vec3(0.0, 5.0, 0.0);
  world.add_body(box);
  for (int k = 0; k < 100; ++k) world.step();
  const Quat expected(Eigen::AngleAxisd(5.0 * 100 * def.dt, Vec3::UnitY()));
  CHECK(world.body(0).o.angularDistance(expected) <= 1e-9);
}

TEST_CASE("invalid distance constraints are rejected", "[constraint][validation]") {
  World world;
  BodyDef ball;
  ball.shape = Shape::sphere(0.5);
  world.add_body(ball);
  world.add_body({Shape::plane(Vec3::UnitY(), 0.0), true});
  CHECK_THROWS_WITH(world.add_distance({0, Vec3::Zero(), kWorldBody, Vec3::Zero(), -1.0}),
                    Catch::Contains("length") && Catch::Contains("-1"));
  CHECK_THROWS_WITH(world.add_distance({5, Vec3::Zero(), kWorldBody, Vec3::Zero(), 1.0}),
                    Catch::Contains("body_a 5"));
  CHECK_THROWS_WITH(world.add_distance({1, Vec3::Zero(), 0, Vec3::Zero(), 1.0}),
                    Catch::Contains("static"));
  CHECK(world.distances().empty());
}

TEST_CASE("a rod that does not collide leaves its two bodies without contacts", "[constraint][distance]") {
  // Two unit boxes overlapping by 0.2 m, and a third overlapping the second: with collide =
  // false on a rod between the first two, only the pair (1, 2) has a manifold; with true, both.
  for (const bool collide : {true, false}) {
    WorldDef def;
    def.gravity = Vec3::Zero();
    World world(def);
    for (int i = 0; i < 3; ++i) {
      BodyDef b;
      b.shape = Shape::box(Vec3::Constant(0.5));
      b.mass = 1.0;
      b.position = Vec3(0.8 * i, 0.0, 0.0);
      world.add_body(b);
    }
    DistanceConstraint d{0, Vec3::Zero(), 1, Vec3::Zero(), 0.8};
    d.collide = collide;
    world.add_distance(d);
    world.step();
    bool pair01 = false;
    bool pair12 = false;
    for (const Manifold& m : world.manifolds()) {
      pair01 = pair01 || (m.body_a == 0 && m.body_b == 1);
      pair12 = pair12 || (m.body_a == 1 && m.body_b == 2);
    }
    INFO("collide " << collide);
    CHECK(pair01 == collide);
    CHECK(pair12);
  }
}

TEST_CASE("a box on a ball joint swings as a physical pendulum about either axis",
          "[constraint][ball_joint]") {
  // A 1 x 0.5 x 0.5 m box (m = 0.25 kg, long axis vertical) hangs from a static body by a ball
  // joint (scenes::add_ball_joint: three rods) at the centre of its top face, d = 0.5 m above its
  // centre, and is sent swinging about z or about x at amplitude theta0 = 0.05 rad. A physical
  // pendulum's period is T = 2 pi sqrt(I_p / (m g d)), I_p = m (1^2 + 0.5^2) / 12 + m d^2 about
  // either axis. Bound 0.5 %: the amplitude adds theta0^2 / 16 = 1.6e-4, the integrator (omega
  // dt)^2 / 24 < 1e-5 at dt = 1/600 s; a joint that held a direction (a hinge about the other
  // axis, or rods pulling the box's top sideways) changes T or stops the swing.
  const double m = 0.25;
  const double d = 0.5;
  const double g = 9.81;
  const double inertia = m * (1.0 + 0.25) / 12.0 + m * d * d;
  const double period = 2.0 * kPi * std::sqrt(inertia / (m * g * d));
  const double omega0 = 0.05 * 2.0 * kPi / period;  // rad/s: amplitude 0.05 rad
  for (const int axis : {0, 2}) {
    WorldDef def;
    def.gravity = Vec3(0.0, -g, 0.0);
    def.dt = 1.0 / 600.0;
    def.collision = false;
    World world(def);
    BodyDef top;
    top.shape = Shape::box(Vec3::Constant(0.25));
    top.is_static = true;
    top.mass = 0.0;
    top.position = Vec3(0.0, 0.75, 0.0);
    const int fixed = world.add_body(top);
    BodyDef link;
    link.shape = Shape::box(Vec3(0.25, 0.5, 0.25));
    link.mass = m;
    link.position = Vec3::Zero();
    // Turning at omega0 about the joint point (0, d, 0): the centre moves at omega x (-d y).
    const Vec3 w = omega0 * Vec3::Unit(axis);
    link.angular_velocity = w;
    link.velocity = w.cross(Vec3(0.0, -d, 0.0));
    const int body = world.add_body(link);
    scenes::add_ball_joint(world, fixed, Vec3(0.0, -0.25, 0.0), body, Vec3(0.0, d, 0.0), 0.25,
                           Vec3(1.0, -1.0, 1.0));
    // The side the centre moves to: x for a swing about z, z for one about x.
    const int side = axis == 0 ? 2 : 0;
    std::vector<double> crossings;  // s: the centre through 0 along `side`, going the first way
    double previous = world.bodies()[1].x[side];
    double largest_gap = 0.0;
    while (world.time() < 3.5 * period) {
      world.step();
      const Body& b = world.bodies()[1];
      const double now = b.x[side];
      if (previous < 0.0 && now >= 0.0) {
        crossings.push_back(world.time() - def.dt * now / (now - previous));
      }
      previous = now;
      const Vec3 joint = b.x + b.rotation() * Vec3(0.0, d, 0.0);
      largest_gap = std::max(largest_gap, (joint - Vec3(0.0, d, 0.0)).norm());
    }
    INFO("swing about axis " << axis << ", " << crossings.size() << " crossings, joint gap "
                             << largest_gap << " m");
    REQUIRE(crossings.size() >= 3);
    const double measured = (crossings.back() - crossings.front()) / (crossings.size() - 1.0);
    INFO("period " << measured << " s against " << period << " s");
    CHECK(std::abs(measured / period - 1.0) < 5e-3);
    CHECK(largest_gap < 1e-3);
  }
}
