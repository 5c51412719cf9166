// The order of convergence of the step in dt, measured: the error at a fixed time against an
// analytic or tightly converged reference for dt = h, h/2, h/4, h/8, and the slope of log(error)
// against log(dt) beside the theory's.
//
// Theory: the engine integrates with semi-implicit (symplectic) Euler, paper Sec. 3.2, Eqs.
// 3.2.1-3.2.3: p_{k+1} = p_k + f dt, x_{k+1} = x_k + p_{k+1} / m dt. Its local error is O(dt^2),
// so the error at a fixed time t = N dt, after N = t / dt steps, is O(dt): order 1. The
// constraint forces come from a solve at the start of each step on the state of that step (Secs.
// 5-7), a first-order splitting as well, so the constrained motion is also of order 1. A measured
// slope is a finite difference of log(error), which carries the O(dt^2) part of the error too:
// for e(dt) = C dt (1 + c dt) the slope between dt and dt/2 is 1 + log2((1 + c dt) / (1 + c dt/2))
// ~ 1 + c dt / (2 ln 2); with |c| dt <= 0.5 at the largest dt it lies within 1 +- 0.2, the band
// asserted ([0.8, 1.2]). A slope near 2 would mean a second-order method (or a reference that is
// itself off by O(dt)); near 0, an error that does not shrink with dt (a bias of the solver).
// docs/findings.md, "Order of convergence in dt", has the measured table.
#include "cps/world.h"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>

using namespace cps;

namespace {

// The time steps of a sweep: h, h/2, h/4, h/8 (s).
constexpr double kLargestStep = 1.0 / 60.0;  // s: the paper's and the scenes' dt
constexpr int kHalvings = 4;

std::array<double, kHalvings> step_sizes() {
  std::array<double, kHalvings> dt{};
  for (int i = 0; i < kHalvings; ++i) dt[static_cast<std::size_t>(i)] = kLargestStep / std::pow(2.0, i);
  return dt;
}

// The least-squares slope of log(error) against log(dt) (dimensionless); errors > 0.
double fitted_slope(const std::array<double, kHalvings>& dt, const std::array<double, kHalvings>& error) {
  double mean_x = 0.0;
  double mean_y = 0.0;
  for (std::size_t i = 0; i < dt.size(); ++i) {
    mean_x += std::log(dt[i]) / dt.size();
    mean_y += std::log(error[i]) / dt.size();
  }
  double sxy = 0.0;
  double sxx = 0.0;
  for (std::size_t i = 0; i < dt.size(); ++i) {
    sxy += (std::log(dt[i]) - mean_x) * (std::log(error[i]) - mean_y);
    sxx += (std::log(dt[i]) - mean_x) * (std::log(dt[i]) - mean_x);
  }
  return sxy / sxx;
}

// Steps `world` to time t (s), which must be a whole number of its steps.
void step_to(World& world, double t) {
  const long long steps = std::llround(t / world.def().dt);
  REQUIRE(std::abs(static_cast<double>(steps) * world.def().dt - t) < 1e-12);
  for (long long k = 0; k < steps; ++k) world.step();
}

// --- A box sliding on the ground with friction -----------------------------------------------
// A cube of half extent a touching the plane y = 0 and started at speed v0 along x, under
// gravity g and friction mu (the paper's fixed limit, Sec. 5.4: mu m |g| shared over the contact
// points). While it slides the friction force is -mu m g: x(t) = v0 t - mu g t^2 / 2 until it
// stops at t = v0 / (mu g). Semi-implicit Euler with that constant force gives
// v_k = v0 - mu g k dt and x_N = sum v_k dt. One detail of the engine: a face that only touches
// the plane (separation 0) is not in contact at the default contact margin 0 (a contact needs
// separation < margin, engine/src/collision.cpp), so the first step is free flight and friction
// acts from the second: x_N = v0 t - mu g dt^2 N (N - 1) / 2 = v0 t - mu g t (t - dt) / 2.
// Its error against x(t) is +mu g t dt / 2: exactly linear in dt, order 1.
struct Slide {
  double v0 = 2.0;      // m/s
  double mu = 0.4;      // dimensionless
  double g = 10.0;      // m/s^2
  double half = 0.5;    // m, the cube's half extent
  double mass = 2.0;    // kg
  double time = 0.25;   // s, before it stops at v0 / (mu g) = 0.5 s
};

// x (m) of the sliding box at s.time, stepped at dt (s).
double slide_distance(const Slide& s, double dt, PushMode push) {
  WorldDef def;
  def.dt = dt;
  def.gravity = Vec3(0.0, -s.g, 0.0);
  def.friction = s.mu;
  def.push = push;
  World world(def);
  BodyDef ground;
  ground.shape = Shape::plane(Vec3::UnitY(), 0.0);
  ground.is_static = true;
  world.add_body(ground);
  BodyDef box;
  box.shape = Shape::box(Vec3::Constant(s.half));
  box.mass = s.mass;
  box.position = Vec3(0.0, s.half, 0.0);
  box.velocity = Vec3(s.v0, 0.0, 0.0);
  const int i = world.add_body(box);
  step_to(world, s.time);
  return world.body(i).x.x();
}

// --- A single pendulum -------------------------------------------------------------------------
// A ball of radius r on a rod of length l from the pivot to its centre (a distance constraint,
// Sec. 5.2), released at rest at angle theta0 from the vertical. The rod acts through the centre,
// so the ball's spin is untouched and the centre moves as a point-mass pendulum,
// theta'' = -(g / l) sin theta, with no small-angle approximation. The reference integrates that
// with classical RK4 at a step of 1e-5 s (error O(step^4), far below the engine's O(dt)).
struct Pendulum {
  double length = 1.0;    // m
  double radius = 0.05;   // m
  double mass = 1.0;      // kg
  double g = 10.0;        // m/s^2
  double theta0 = 0.1;    // rad (5.7 degrees)
  double time = 1.5;      // s, about 3/4 of a period (2 pi sqrt(l / g) = 1.99 s): passing the
                          // bottom, where the angle's error is its phase error times its speed
};

// theta (rad) of the point-mass pendulum at p.time by RK4 at a step of at most `step` (s).
double reference_angle(const Pendulum& p, double step) {
  const auto accel = [&](double th) { return -p.g / p.length * std::sin(th); };
  double th = p.theta0;
  double w = 0.0;
  const long long n = std::llround(std::ceil(p.time / step));
  const double h = p.time / static_cast<double>(n);
  for (long long k = 0; k < n; ++k) {
    const double k1t = w, k1w = accel(th);
    const double k2t = w + 0.5 * h * k1w, k2w = accel(th + 0.5 * h * k1t);
    const double k3t = w + 0.5 * h * k2w, k3w = accel(th + 0.5 * h * k2t);
    const double k4t = w + h * k3w, k4w = accel(th + h * k3t);
    th += h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
    w += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  }
  return th;
}

// theta (rad) of the engine's pendulum (pivot at (0, 2, 0), swinging in the x-y plane) at
// p.time, stepped at dt (s).
double pendulum_angle(const Pendulum& p, double dt, PushMode push) {
  WorldDef def;
  def.dt = dt;
  def.gravity = Vec3(0.0, -p.g, 0.0);
  def.push = push;
  World world(def);
  const Vec3 pivot(0.0, 2.0, 0.0);
  BodyDef ball;
  ball.shape = Shape::sphere(p.radius);
  ball.mass = p.mass;
  ball.position = pivot + p.length * Vec3(std::sin(p.theta0), -std::cos(p.theta0), 0.0);
  const int i = world.add_body(ball);
  DistanceConstraint rod;
  rod.body_a = i;
  rod.local_a = Vec3::Zero();
  rod.body_b = kWorldBody;
  rod.local_b = pivot;
  rod.length = p.length;
  world.add_distance(rod);
  step_to(world, p.time);
  const Vec3 d = world.body(i).x - pivot;
  return std::atan2(d.x(), -d.y());
}

}  // namespace

TEST_CASE("a box sliding with friction converges at order 1 in dt, as semi-implicit Euler's "
          "closed form says",
          "[convergence]") {
  const Slide s;
  const double exact = s.v0 * s.time - 0.5 * s.mu * s.g * s.time * s.time;
  for (const PushMode push : {PushMode::baumgarte, PushMode::split, PushMode::split_impulse,
                              PushMode::soft, PushMode::ngs}) {
    const auto dt = step_sizes();
    std::array<double, kHalvings> error{};
    for (std::size_t i = 0; i < dt.size(); ++i) {
      const double x = slide_distance(s, dt[i], push);
      error[i] = std::abs(x - exact);
      // The closed form of the discrete motion: x_N = v0 t - mu g t (t - dt) / 2.
      const double discrete = s.v0 * s.time - 0.5 * s.mu * s.g * s.time * (s.time - dt[i]);
      INFO("push " << name_of(push) << ", dt = " << dt[i] << " s: x = " << x << " m, closed form "
                   << discrete << " m, exact " << exact << " m");
      // The soft step integrates in substeps (WorldDef::soft_substeps) with springy rows, so the
      // closed form of one Euler step per dt is not its motion; its order is checked below.
      if (push != PushMode::soft) CHECK(x == Approx(discrete).margin(1e-9));
      if (i > 0) CHECK(error[i] < error[i - 1]);
    }
    const double slope = fitted_slope(dt, error);
    INFO("push " << name_of(push) << ": errors " << error[0] << ", " << error[1] << ", " << error[2]
                 << ", " << error[3] << " m; slope " << slope);
    CHECK(slope >= 0.8);
    CHECK(slope <= 1.2);
  }
}

TEST_CASE("a pendulum on a distance constraint converges at order 1 in dt against an RK4 "
          "reference",
          "[convergence]") {
  const Pendulum p;
  const double reference = reference_angle(p, 1e-5);
  // The reference is converged: halving its step moves it by far less than the smallest error.
  REQUIRE(std::abs(reference_angle(p, 2e-5) - reference) < 1e-12);
  for (const PushMode push : {PushMode::baumgarte, PushMode::split, PushMode::split_impulse,
                              PushMode::soft, PushMode::ngs}) {
    const auto dt = step_sizes();
    std::array<double, kHalvings> error{};
    for (std::size_t i = 0; i < dt.size(); ++i) {
      error[i] = std::abs(pendulum_angle(p, dt[i], push) - reference);
      INFO("push " << name_of(push) << ", dt = " << dt[i] << " s: angle error " << error[i] << " rad");
      if (i > 0) CHECK(error[i] < error[i - 1]);
    }
    const double slope = fitted_slope(dt, error);
    INFO("push " << name_of(push) << ": errors " << error[0] << ", " << error[1] << ", " << error[2]
                 << ", " << error[3] << " rad; slope " << slope);
    CHECK(slope >= 0.8);
    CHECK(slope <= 1.2);
  }
}
