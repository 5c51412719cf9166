// Collision detection (paper Sec. 4): box-plane and box-box manifolds against geometry worked
// out by hand.
#include "contact_recycling.h"
#include "scene.h"
#include "state_hash.h"

#include "cps/collision.h"
#include "cps/world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace cps;

namespace {

OrientedBox box_at(const Vec3& c, const Vec3& e, const Mat3& R = Mat3::Identity()) {
  return {c, R, e};
}

Mat3 rotation(double angle, const Vec3& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// Adds a body of `shape` at `at` to world, turned at random (four draws of `random`, planes
// drawn for too and kept unturned).
void add_turned(World& world, std::mt19937& random, const Shape& shape, bool is_static, const Vec3& at) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  BodyDef b;
  b.shape = shape;
  b.is_static = is_static;
  b.position = at;
  b.orientation = Quat(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5).normalized();
  if (shape.kind == ShapeKind::plane) b.orientation = Quat::Identity();
  world.add_body(b);
}

}  // namespace

TEST_CASE("a box sunk 0.1 m into the ground gives 4 contacts", "[collision]") {
  Manifold m;
  REQUIRE(collide_box_plane(box_at(Vec3(0, 0.9, 0), Vec3::Ones()), Vec3::UnitY(), 0.0, m) == 4);
  for (int i = 0; i < m.count; ++i) {
    const Contact& c = m.contacts[static_cast<std::size_t>(i)];
    CHECK(c.normal.isApprox(Vec3::UnitY()));
    CHECK(c.depth == Approx(0.1).margin(1e-12));
    CHECK(c.point.y() == Approx(-0.05).margin(1e-12));  // midway between vertex and plane
    CHECK(std::abs(c.point.x()) == Approx(1.0).margin(1e-12));
    CHECK(std::abs(c.point.z()) == Approx(1.0).margin(1e-12));
  }
}

TEST_CASE("the box-plane normal points from body a to body b", "[collision]") {
  Body ground = make_body({Shape::plane(Vec3::UnitY(), 0.0), true});
  BodyDef def;
  def.shape = Shape::box(Vec3::Ones());
  def.position = Vec3(0, 0.95, 0);
  Body box = make_body(def);
  Manifold m;
  REQUIRE(collide(ground, box, m) == 4);
  CHECK(m.contacts[0].normal.isApprox(Vec3::UnitY()));
  REQUIRE(collide(box, ground, m) == 4);
  CHECK(m.contacts[0].normal.isApprox(-Vec3::UnitY()));
  CHECK(m.contacts[0].depth == Approx(0.05));
}

TEST_CASE("boxes face to face give 4 contacts with the right normal and depth", "[collision]") {
  SECTION("aligned") {
    Manifold m;
    REQUIRE(collide_box_box(box_at(Vec3::Zero(), Vec3::Ones()),
                            box_at(Vec3(0, 1.9, 0), Vec3::Ones()), m) == 4);
    for (int i = 0; i < m.count; ++i) {
      const Contact& c = m.contacts[static_cast<std::size_t>(i)];
      CHECK(c.normal.isApprox(Vec3::UnitY()));
      CHECK(c.depth == Approx(0.1).margin(1e-12));
      CHECK(c.point.y() == Approx(0.95).margin(1e-12));
      CHECK(std::abs(c.point.x()) == Approx(1.0).margin(1e-12));
      CHECK(std::abs(c.point.z()) == Approx(1.0).margin(1e-12));
    }
  }
  SECTION("offset sideways: the manifold is the overlap of the two faces") {
    Manifold m;
    REQUIRE(collide_box_box(box_at(Vec3::Zero(), Vec3::Ones()),
                            box_at(Vec3(0.5, -1.8, 0.25), Vec3::Ones()), m) == 4);
    for (int i = 0; i < m.count; ++i) {
      const Contact& c = m.contacts[static_cast<std::size_t>(i)];
      CHECK(c.normal.isApprox(-Vec3::UnitY()));  // from a (above) to b (below)
      CHECK(c.depth == Approx(0.2).margin(1e-12));
      const bool x_on_edge = std::abs(c.point.x() + 0.5) < 1e-12 || std::abs(c.point.x() - 1.0) < 1e-12;
      const bool z_on_edge = std::abs(c.point.z() + 0.75) < 1e-12 || std::abs(c.point.z() - 1.0) < 1e-12;
      CHECK(x_on_edge);
      CHECK(z_on_edge);
    }
  }
}

TEST_CASE("a box turned 45 degrees on another gives a manifold inside the overlap",
          "[collision]") {
  // The top face of the lower box and the bottom face of the turned box overlap in a regular
  // octagon; clipping gives its 8 corners, all at the same depth.
  const Mat3 R = rotation(M_PI / 4.0, Vec3::UnitY());
  const OrientedBox lower = box_at(Vec3::Zero(), Vec3::Ones());
  const OrientedBox upper = box_at(Vec3(0, 1.95, 0), Vec3::Ones(), R);
  Manifold m;
  REQUIRE(collide_box_box(lower, upper, m) == 8);
  for (int i = 0; i < m.count; ++i) {
    const Contact& c = m.contacts[static_cast<std::size_t>(i)];
    CHECK(c.normal.isApprox(Vec3::UnitY()));
    CHECK(c.depth == Approx(0.05).margin(1e-12));
    // Inside the lower box's top face and inside the turned box's bottom face.
    CHECK(std::abs(c.point.x()) <= 1.0 + 1e-12);
    CHECK(std::abs(c.point.z()) <= 1.0 + 1e-12);
    const Vec3 local = R.transpose() * (c.point - upper.c);
    CHECK(std::abs(local.x()) <= 1.0 + 1e-12);
    CHECK(std::abs(local.z()) <= 1.0 + 1e-12);
    // On the boundary of one of the two squares: an octagon corner.
    const double on_lower = std::max(std::abs(c.point.x()), std::abs(c.point.z()));
    const double on_upper = std::max(std::abs(local.x()), std::abs(local.z()));
    CHECK(std::max(on_lower, on_upper) == Approx(1.0).margin(1e-12));
  }
}

TEST_CASE("separated boxes give no contact", "[collision]") {
  Manifold m;
  SECTION("along a face normal") {
    CHECK(collide_box_box(box_at(Vec3::Zero(), Vec3::Ones()),
                          box_at(Vec3(0, 2.01, 0), Vec3::Ones()), m) == 0);
  }
  SECTION("only along an edge-edge axis") {
    // a turned 45 degrees about z shows an edge along z at x = sqrt 2; b turned 45 degrees about
    // y shows an edge along y at x = -sqrt 2 from its centre. With the centres 2 sqrt 2 + 0.05
    // apart on x the edges miss by 0.05 m, while every face axis still shows an overlap.
    const OrientedBox a = box_at(Vec3::Zero(), Vec3::Ones(), rotation(M_PI / 4, Vec3::UnitZ()));
    const OrientedBox b = box_at(Vec3(2.0 * std::sqrt(2.0) + 0.05, 0, 0), Vec3::Ones(),
                                 rotation(M_PI / 4, Vec3::UnitY()));
    CHECK(collide_box_box(a, b, m) == 0);
    CHECK(m.count == 0);
  }
}

TEST_CASE("crossed edges give one contact at their closest points", "[collision]") {
  // As above, but the edges cross 0.05 m deep: the closest points are (sqrt 2, 0, 0) on a's edge
  // and (sqrt 2 - 0.05, 0, 0) on b's edge; the contact lies midway, the normal is +x.
  const double s2 = std::sqrt(2.0);
  const OrientedBox a = box_at(Vec3::Zero(), Vec3::Ones(), rotation(M_PI / 4, Vec3::UnitZ()));
  const OrientedBox b =
      box_at(Vec3(2.0 * s2 - 0.05, 0, 0), Vec3::Ones(), rotation(M_PI / 4, Vec3::UnitY()));
  Manifold m;
  REQUIRE(collide_box_box(a, b, m) == 1);
  const Contact& c = m.contacts[0];
  CHECK(c.normal.isApprox(Vec3::UnitX()));
  CHECK(c.depth == Approx(0.05).margin(1e-12));
  CHECK((c.point - Vec3(s2 - 0.025, 0, 0)).norm() <= 1e-12);
}

TEST_CASE("the edge-edge contact follows the edges when they are offset", "[collision]") {
  // Shift b by 0.3 along z and 0.2 along y: a's edge runs along z, b's along y, so the closest
  // points move to (sqrt 2, 0, 0.3) on a and (sqrt 2 - 0.05, 0, 0.3) on b.
  const double s2 = std::sqrt(2.0);
  const OrientedBox a = box_at(Vec3::Zero(), Vec3::Ones(), rotation(M_PI / 4, Vec3::UnitZ()));
  const OrientedBox b =
      box_at(Vec3(2.0 * s2 - 0.05, 0.2, 0.3), Vec3::Ones(), rotation(M_PI / 4, Vec3::UnitY()));
  Manifold m;
  REQUIRE(collide_box_box(a, b, m) == 1);
  CHECK((m.contacts[0].point - Vec3(s2 - 0.025, 0.0, 0.3)).norm() <= 1e-12);
}

TEST_CASE("sphere contacts: plane, sphere, coincident centres", "[collision][sphere]") {
  Manifold m;
  SECTION("a sphere 0.1 m into a plane") {
    REQUIRE(collide_sphere_plane(Vec3(0, 0.4, 0), 0.5, Vec3::UnitY(), 0.0, m) == 1);
    CHECK(m.contacts[0].normal.isApprox(Vec3::UnitY()));
    CHECK(m.contacts[0].depth == Approx(0.1).margin(1e-12));
    CHECK((m.contacts[0].point - Vec3(0, -0.05, 0)).norm() <= 1e-12);
  }
  SECTION("a sphere above a plane") {
    CHECK(collide_sphere_plane(Vec3(0, 0.51, 0), 0.5, Vec3::UnitY(), 0.0, m) == 0);
  }
  SECTION("two overlapping spheres") {
    REQUIRE(collide_sphere_sphere(Vec3(0, 0, 0), 0.5, Vec3(0.6, 0.8, 0), 0.5, m) == 0);
    REQUIRE(collide_sphere_sphere(Vec3(0, 0, 0), 0.5, Vec3(0.54, 0.72, 0), 0.5, m) == 1);
    CHECK(m.contacts[0].normal.isApprox(Vec3(0.6, 0.8, 0)));
    CHECK(m.contacts[0].depth == Approx(0.1).margin(1e-12));  // |c_b - c_a| = 0.9
    CHECK((m.contacts[0].point - 0.45 * Vec3(0.6, 0.8, 0)).norm() <= 1e-12);
  }
  SECTION("coincident centres still give a unit normal and the full depth") {
    REQUIRE(collide_sphere_sphere(Vec3(1, 2, 3), 0.5, Vec3(1, 2, 3), 0.25, m) == 1);
    CHECK(m.contacts[0].normal.norm() == Approx(1.0));
    CHECK(m.contacts[0].depth == Approx(0.75));
  }
}

TEST_CASE("box-sphere contacts by the closest point of the box", "[collision][sphere]") {
  const Mat3 R = rotation(0.3, Vec3(1, 2, 3));
  const OrientedBox box = box_at(Vec3(1, 0, 0), Vec3(1, 2, 3), R);
  Manifold m;
  SECTION("facing a face") {
    const Vec3 c = box.c + R * Vec3(1.4, 0.5, -1.0);  // 0.4 m out of the +x face
    REQUIRE(collide_box_sphere(box, c, 0.5, m) == 1);
    CHECK(m.contacts[0].normal.isApprox(R.col(0)));
    CHECK(m.contacts[0].depth == Approx(0.1).margin(1e-12));
  }
  SECTION("facing a corner") {
    const Vec3 corner = box.c + R * Vec3(1, 2, 3);
    const Vec3 dir = R * Vec3(1, 1, 1).normalized();
    REQUIRE(collide_box_sphere(box, corner + 0.45 * dir, 0.5, m) == 1);
    CHECK(m.contacts[0].normal.isApprox(dir));
    CHECK(m.contacts[0].depth == Approx(0.05).margin(1e-12));
    CHECK(collide_box_sphere(box, corner + 0.55 * dir, 0.5, m) == 0);
  }
  SECTION("centre inside the box leaves through the nearest face") {
    const Vec3 c = box.c + R * Vec3(0.2, 1.7, 0.5);  // 0.3 m below the +y face
    REQUIRE(collide_box_sphere(box, c, 0.5, m) == 1);
    CHECK(m.contacts[0].normal.isApprox(R.col(1)));
    CHECK(m.contacts[0].depth == Approx(0.8).margin(1e-12));
  }
  SECTION("the dispatcher orients the normal from body a to body b") {
    BodyDef sphere_def;
    sphere_def.shape = Shape::sphere(0.5);
    sphere_def.position = Vec3(0, 1.4, 0);
    BodyDef box_def;
    box_def.shape = Shape::box(Vec3::Ones());
    const Body s = make_body(sphere_def);
    const Body b = make_body(box_def);
    REQUIRE(collide(s, b, m) == 1);
    CHECK(m.contacts[0].normal.isApprox(-Vec3::UnitY()));
    REQUIRE(collide(b, s, m) == 1);
    CHECK(m.contacts[0].normal.isApprox(Vec3::UnitY()));
  }
}

TEST_CASE("a speculative margin reports near features with a negative depth", "[collision]") {
  Manifold m;
  // 2 mm apart: nothing without a margin, one contact per vertex / point with a 5 mm margin.
  CHECK(collide_box_plane(box_at(Vec3(0, 1.002, 0), Vec3::Ones()), Vec3::UnitY(), 0.0, m) == 0);
  REQUIRE(collide_box_plane(box_at(Vec3(0, 1.002, 0), Vec3::Ones()), Vec3::UnitY(), 0.0, m, 0.005) == 4);
  CHECK(m.contacts[0].depth == Approx(-0.002).margin(1e-12));
  m.count = 0;
  REQUIRE(collide_box_box(box_at(Vec3::Zero(), Vec3::Ones()), box_at(Vec3(0, 2.002, 0), Vec3::Ones()),
                          m, 0.005) == 4);
  CHECK(m.contacts[0].depth == Approx(-0.002).margin(1e-12));
  m.count = 0;
  CHECK(collide_box_box(box_at(Vec3::Zero(), Vec3::Ones()), box_at(Vec3(0, 2.01, 0), Vec3::Ones()),
                        m, 0.005) == 0);
  REQUIRE(collide_sphere_sphere(Vec3::Zero(), 0.5, Vec3(1.003, 0, 0), 0.5, m, 0.005) == 1);
  CHECK(m.contacts[0].depth == Approx(-0.003).margin(1e-12));
}

// The broad phase (a hashed grid, World::collide) must hand the narrow phase exactly the pairs
// of the plain definition, in index order: every pair a < b, not both static, that is a plane
// with a movable body or whose axis-aligned bounds (grown by half the margin each) overlap. A
// crowded random world with bodies of 0.05 to 2 m, a 60 m static slab (wider than the grid's
// cells) and planes between the other bodies is checked against that definition evaluated
// over all pairs; once as it is (the grid numbers its cells densely) and once with one more body
// 1e7 m away (the grid's box is then too large and it hashes its rows). On two threads the
// broad phase and the narrow phase share the work and must give the same manifolds.
TEST_CASE("the broad phase finds the manifolds of the all-pairs test, in index order",
          "[collision][broad]") {
  const double margin = GENERATE(0.0, 0.02);
  const int threads = GENERATE(1, 2);
  // 0: the mixed world (dense grid); 1: the same with one body 1e7 m away (hashed rows);
  // 2: 600 small balls in two clusters 400 m apart (hashed rows that share buckets); 3: 30
  // bodies in a 2 m box (a small world: every pair tested, no grid).
  const int layout = GENERATE(0, 1, 2, 3);
  WorldDef def;
  def.contact_margin = margin;
  def.threads = threads;
  World world(def);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto add = [&](const Shape& shape, bool is_static, const Vec3& at) {
    add_turned(world, random, shape, is_static, at);
  };
  add(Shape::plane(Vec3::UnitY(), 0.0), true, Vec3::Zero());
  if (layout == 2) {
    for (int i = 0; i < 600; ++i) {
      const Vec3 at = Vec3(2.0 * unit(random), 2.0 * unit(random), 2.0 * unit(random)) +
                      (i % 2 == 0 ? Vec3::Zero() : Vec3(400.0, 0.0, 300.0));
      add(Shape::sphere(0.1 + 0.05 * unit(random)), false, at);
    }
  }
  for (int i = 0; i < 30 && layout == 3; ++i) {
    const Vec3 at(2.0 * unit(random), 0.3 + 2.0 * unit(random), 2.0 * unit(random));
    const double size = 0.2 + 0.4 * unit(random);
    if (i % 10 == 0) {
      add(Shape::box(Vec3::Constant(size)), true, at);
    } else if (i % 2 == 0) {
      add(Shape::box(Vec3(size, 0.5 * size + 0.05, 0.8 * size)), false, at);
    } else {
      add(Shape::sphere(size), false, at);
    }
  }
  for (int i = 0; i < 400 && layout < 2; ++i) {
    const Vec3 at(8.0 * unit(random) - 4.0, 6.0 * unit(random), 8.0 * unit(random) - 4.0);
    const double size = 0.05 + (i % 7 == 0 ? 1.95 : 0.6) * unit(random);
    if (i == 100) add(Shape::box(Vec3(30.0, 0.2, 30.0)), true, Vec3(0.0, 1.0, 0.0));
    if (i == 200) add(Shape::plane(Vec3(1.0, 1.0, 0.0), -1.0), true, Vec3::Zero());
    if (i == 300 && layout == 1) add(Shape::box(Vec3::Constant(0.5)), false, Vec3(1e7, 3.0, -1e7));
    if (i % 50 == 0) {
      add(Shape::box(Vec3::Constant(size)), true, at);  // static boxes among the others
    } else if (i % 2 == 0) {
      add(Shape::box(Vec3(size, 0.5 * size + 0.05, 0.8 * size)), false, at);
    } else {
      add(Shape::sphere(size), false, at);
    }
  }
  const std::vector<Body> before = world.bodies();  // the step collides this state
  world.step();

  const auto bounds = [&](const Body& b, Vec3& lo, Vec3& hi) {
    const Vec3 half = b.shape.kind == ShapeKind::box
                          ? Vec3(b.rotation().cwiseAbs() * b.shape.half_extents)
                          : Vec3(Vec3::Constant(b.shape.radius));
    lo = b.x - half - Vec3::Constant(0.5 * margin);
    hi = b.x + half + Vec3::Constant(0.5 * margin);
  };
  std::vector<Manifold> expected;
  const int n = static_cast<int>(before.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const Body& A = before[static_cast<std::size_t>(a)];
      const Body& B = before[static_cast<std::size_t>(b)];
      if (A.is_static() && B.is_static()) continue;
      const bool a_plane = A.shape.kind == ShapeKind::plane;
      const bool b_plane = B.shape.kind == ShapeKind::plane;
      if (!a_plane && !b_plane) {
        Vec3 lo_a, hi_a, lo_b, hi_b;
        bounds(A, lo_a, hi_a);
        bounds(B, lo_b, hi_b);
        if ((lo_b.array() > hi_a.array()).any() || (lo_a.array() > hi_b.array()).any()) continue;
      }
      Manifold m;
      m.body_a = a;
      m.body_b = b;
      if (collide(A, B, m, margin) > 0) expected.push_back(m);
    }
  }
  const std::vector<Manifold>& found = world.manifolds();
  REQUIRE(expected.size() > (layout == 3 ? 20u : 200u));  // crowded: the test has pairs to find
  REQUIRE(found.size() == expected.size());
  for (std::size_t k = 0; k < found.size(); ++k) {
    INFO("manifold " << k);
    REQUIRE(found[k].body_a == expected[k].body_a);
    REQUIRE(found[k].body_b == expected[k].body_b);
    REQUIRE(found[k].count == expected[k].count);
    for (int i = 0; i < found[k].count; ++i) {
      const auto c = static_cast<std::size_t>(i);
      CHECK(found[k].contacts[c].point == expected[k].contacts[c].point);
      CHECK(found[k].contacts[c].depth == expected[k].contacts[c].depth);
    }
  }
}

// A plane is a candidate only with the bodies whose bounds come within half the margin of it: a
// box tilted about two axes, its lowest corner just inside or just outside the contact margin
// above a tilted plane, gets its speculative contact or no candidate pair at all; alone (every
// pair of bounds tested) and among 40 far boxes (the grid), on one and two threads.
TEST_CASE("a plane pairs only with the bodies that come within the margin of it", "[collision][broad]") {
  const double margin = 0.01;
  const bool grid = GENERATE(false, true);
  const int threads = GENERATE(1, 2);
  const double gap = GENERATE(0.99, 1.01);  // the lowest corner's height over the margin
  WorldDef def;
  def.contact_margin = margin;
  def.gravity = Vec3::Zero();
  def.threads = threads;
  World world(def);
  const Vec3 normal = Vec3(0.3, 1.0, -0.2).normalized();
  BodyDef plane;
  plane.shape = Shape::plane(normal, 0.5);
  plane.is_static = true;
  world.add_body(plane);
  BodyDef box;
  box.shape = Shape::box(Vec3(0.5, 0.3, 0.2));
  box.orientation = Quat(Eigen::AngleAxisd(0.4, Vec3::UnitX()) * Eigen::AngleAxisd(0.7, Vec3::UnitZ()));
  // The corner lowest along the normal, then the box lifted so that it lies gap * margin above.
  const Mat3 R = box.orientation.toRotationMatrix();
  double lowest = kInfinity;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 sign((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0, (corner & 4) ? 1.0 : -1.0);
    lowest = std::min(lowest, normal.dot(R * sign.cwiseProduct(box.shape.half_extents)));
  }
  box.position = (0.5 - lowest + gap * margin) * normal;
  world.add_body(box);
  for (int i = 0; grid && i < 40; ++i) {
    BodyDef far = box;
    far.position = Vec3(3.0 * (i % 8), 50.0 + 3.0 * (i / 8), 0.0);
    world.add_body(far);
  }
  world.step();
  INFO("grid " << grid << ", threads " << threads << ", gap " << gap);
  const std::vector<Manifold>& found = world.manifolds();
  if (gap < 1.0) {
    REQUIRE(found.size() == 1u);
    CHECK(found[0].count == 1);
    CHECK(found[0].contacts[0].depth == Approx(-gap * margin).margin(1e-12));
    CHECK(world.counters().pairs_tested == 1);
  } else {
    CHECK(found.empty());
    // The box's bounds reach further along the normal than its corner: it may stay a candidate,
    // but none of the 40 boxes 50 m up does, nor do they pair with each other.
    CHECK(world.counters().pairs_tested <= 1);
  }
}

namespace {

// The area (m^2) of the convex polygon through `points` (in the plane y = const), taken in
// angular order about their mean.
double polygon_area_xz(std::vector<Vec3> points) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p / static_cast<double>(points.size());
  std::sort(points.begin(), points.end(), [&mean](const Vec3& a, const Vec3& b) {
    return std::atan2(a.z() - mean.z(), a.x() - mean.x()) < std::atan2(b.z() - mean.z(), b.x() - mean.x());
  });
  double twice = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    const Vec3& q = points[(i + 1) % points.size()];
    twice += p.x() * q.z() - q.x() * p.z();
  }
  return 0.5 * std::abs(twice);
}

}  // namespace

TEST_CASE("reducing a manifold to 4 points keeps clipped points that hold the contact area",
          "[collision][manifold]") {
  // The turned box's octagon of 8 points (above) is reduced to 4 of its corners. A box resting on
  // the kept points alone must still be supported: its centre's projection (the octagon's centre,
  // the origin) lies inside them, and they span at least half the octagon's area (a square on
  // alternate corners spans 0.71 of a regular octagon; the best 4 of the 8 no more than that).
  // Then the box is tilted: its deepest point must be among those kept, since it carries the
  // most load.
  const Mat3 R = rotation(M_PI / 4.0, Vec3::UnitY());
  const OrientedBox lower = box_at(Vec3::Zero(), Vec3::Ones());
  for (const double tilt : {0.0, 0.01}) {
    CAPTURE(tilt);
    const OrientedBox upper = box_at(Vec3(0, 1.95, 0), Vec3::Ones(), rotation(tilt, Vec3::UnitX()) * R);
    Manifold m;
    REQUIRE(collide_box_box(lower, upper, m) == 8);
    const Manifold full = m;
    reduce_manifold(m, 0.02);
    REQUIRE(m.count == 4);
    std::vector<Vec3> all;
    std::vector<Vec3> kept;
    double deepest = -kInfinity;
    for (int i = 0; i < full.count; ++i) {
      all.push_back(full.contacts[static_cast<std::size_t>(i)].point);
      deepest = std::max(deepest, full.contacts[static_cast<std::size_t>(i)].depth);
    }
    double deepest_kept = -kInfinity;
    for (int i = 0; i < m.count; ++i) {
      const Contact& c = m.contacts[static_cast<std::size_t>(i)];
      kept.push_back(c.point);
      deepest_kept = std::max(deepest_kept, c.depth);
      bool found = false;  // one of the clipped points, unchanged
      for (int j = 0; j < full.count; ++j) {
        const Contact& o = full.contacts[static_cast<std::size_t>(j)];
        found = found || (o.feature == c.feature && o.point == c.point && o.depth == c.depth &&
                          o.normal == c.normal);
      }
      CHECK(found);
    }
    CHECK(deepest_kept == deepest);
    const double area = polygon_area_xz(kept);
    CHECK(area >= 0.5 * polygon_area_xz(all));
    // The origin inside the kept quadrilateral: the four triangles it makes with the edges
    // add up to the quadrilateral's area.
    double around = 0.0;
    std::vector<Vec3> sorted = kept;
    std::sort(sorted.begin(), sorted.end(),
              [](const Vec3& a, const Vec3& b) { return std::atan2(a.z(), a.x()) < std::atan2(b.z(), b.x()); });
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      const Vec3& p = sorted[i];
      const Vec3& q = sorted[(i + 1) % sorted.size()];
      around += 0.5 * std::abs(p.x() * q.z() - q.x() * p.z());
    }
    CHECK(around == Approx(area).epsilon(1e-9));
  }
  // At most 4 points: left as they are.
  Manifold four;
  REQUIRE(collide_box_box(lower, box_at(Vec3(0, 1.95, 0), Vec3::Ones()), four) == 4);
  const Manifold before = four;
  reduce_manifold(four, 0.02);
  CHECK(four.count == 4);
  for (int i = 0; i < 4; ++i) CHECK(four.contacts[static_cast<std::size_t>(i)].point == before.contacts[static_cast<std::size_t>(i)].point);
}

TEST_CASE("contact recycling keeps a manifold while the bodies barely move, with the depths a "
          "new clip gives", "[collision][recycling]") {
  // A box of 1 m resting 1 cm deep on the ground. Moved rigidly by less than the recycling
  // distance, its manifold is kept: the same feature ids, each body's anchor (world vector from
  // its centre) as made, so a point stays where the ground holds it and the box holds it the
  // box's motion further on (anchor_shift), its depth changed by the box's motion along the
  // normal, exactly what clipping again gives for a move along the normal and a slide within the
  // face. Turned, the box keeps its anchors unturned (Box3D's recycling). Moved further than the distance, or
  // turned by more than 10 degrees, it is not kept (the bound of contact_recycling.h: the
  // relative motion plus 2 sin(turn / 2) times the bounding radius, 0.866 m).
  std::vector<Body> bodies;
  bodies.push_back(make_body({Shape::plane(Vec3::UnitY(), 0.0), true}));
  BodyDef box_def;
  box_def.shape = Shape::box(Vec3::Constant(0.5));
  box_def.position = Vec3(0.0, 0.49, 0.0);
  bodies.push_back(make_body(box_def));
  Manifold first;
  REQUIRE(collide(bodies[0], bodies[1], first, 0.02) == 4);
  first.body_a = 0;  // as the collide stage names them
  first.body_b = 1;
  ContactRecycler recycler;
  // The lookups below ask for (0, 1) or later pairs, in ascending order: one cursor serves them.
  ContactRecycler::Cursor fresh_cursor;
  recycler.begin_step();
  recycler.keep(first, bodies, ContactRecycler::kNone);
  recycler.end_step();
  // A thread's cursor starts at the first cached pair not below its first pair.
  CHECK(recycler.cursor_at(0, 1).at == 0);
  CHECK(recycler.cursor_at(0, 2).at == 1);
  CHECK(recycler.cursor_at(0, 0).at == 0);

  const auto moved = [&](const Vec3& dx, double turn_deg) {
    std::vector<Body> b = bodies;
    b[1].x += dx;
    b[1].o = Quat(Eigen::AngleAxisd(turn_deg * M_PI / 180.0, Vec3::UnitY())) * b[1].o;
    return b;
  };
  {
    const std::vector<Body> b = moved(Vec3(0.01, -0.003, 0.02), 0.0);
    recycler.begin_step();
    Manifold kept;
    ContactRecycler::Cursor cursor;
    REQUIRE(recycler.recycle(0, 1, b, 0.05, kept, cursor));
    CHECK(cursor.found == 0);
    Manifold fresh;
    REQUIRE(collide(b[0], b[1], fresh, 0.02) == 4);
    REQUIRE(kept.count == 4);
    for (int i = 0; i < 4; ++i) {
      const Contact& k = kept.contacts[static_cast<std::size_t>(i)];
      const Contact& o = first.contacts[static_cast<std::size_t>(i)];
      CHECK(k.feature == o.feature);
      CHECK(k.normal == o.normal);
      CHECK((k.point - o.point).norm() < 1e-12);  // the ground did not move
      CHECK((point_on_b(kept, k) - (o.point + Vec3(0.01, -0.003, 0.02))).norm() < 1e-12);
      CHECK(k.depth == Approx(o.depth + 0.003).margin(1e-12));
      bool same = false;  // the new clip's point of the same feature: the same depth
      for (int j = 0; j < 4; ++j) {
        const Contact& f = fresh.contacts[static_cast<std::size_t>(j)];
        if (f.feature == k.feature) same = std::abs(f.depth - k.depth) < 1e-12;
      }
      CHECK(same);
    }
    recycler.keep(kept, b, cursor.found);
    recycler.end_step();
  }
  // The motion adds up from the pose of the clip, not from the last recycling: 0.03 m more
  // passes the 0.05 m distance.
  {
    recycler.begin_step();
    Manifold kept;
    CHECK_FALSE(recycler.recycle(0, 1, moved(Vec3(0.04, 0.0, 0.03), 0.0), 0.05, kept, fresh_cursor));
    recycler.end_step();
  }
  // Turns: 3 degrees moves the box's corners by 2 sin(1.5 deg) 0.866 = 0.045 m, kept at 0.05;
  // 12 degrees is past the turn limit at any distance.
  recycler.begin_step();
  recycler.keep(first, bodies, ContactRecycler::kNone);
  recycler.end_step();
  recycler.begin_step();
  Manifold kept;
  CHECK(recycler.recycle(0, 1, moved(Vec3::Zero(), 3.0), 0.05, kept, fresh_cursor));
  for (int i = 0; i < kept.count; ++i) {  // a turn about the normal: the same anchors and depths
    const Contact& k = kept.contacts[static_cast<std::size_t>(i)];
    const Contact& o = first.contacts[static_cast<std::size_t>(i)];
    CHECK((k.point - o.point).norm() < 1e-12);
    CHECK((point_on_b(kept, k) - o.point).norm() < 1e-12);
    CHECK(k.depth == Approx(o.depth).margin(1e-12));
  }
  recycler.begin_step();
  CHECK_FALSE(recycler.recycle(0, 1, moved(Vec3::Zero(), 3.0), 0.04, kept, fresh_cursor));
  recycler.begin_step();
  CHECK_FALSE(recycler.recycle(0, 1, moved(Vec3::Zero(), 12.0), 100.0, kept, fresh_cursor));
  // Another pair than the cached one is never recycled.
  recycler.begin_step();
  CHECK_FALSE(recycler.recycle(0, 2, bodies, 0.05, kept, fresh_cursor));
}

TEST_CASE("a world with contact recycling and reduced manifolds steps its copy as itself",
          "[collision][recycling]") {
  // The recycled manifolds are part of the state a step depends on: a copy made mid-run must
  // keep them and end bit for bit where the original ends. The pile recycles most of its
  // manifolds (a check that the test exercises recycling at all).
  const scenes::Scene* scene = scenes::find_scene("pyramid_100");
  REQUIRE(scene != nullptr);
  scenes::Run run = scenes::make_run(*scene);
  WorldDef def = run.world.def();
  def.contact_margin = 0.02;
  def.contact_recycle_distance = 0.05;
  def.manifold_points = ManifoldPoints::four;
  def.warm_start = 0.8;
  run.world.set_def(def);
  for (int k = 0; k < 120; ++k) run.world.step();
  CHECK(run.world.counters().recycled > run.world.counters().steps * 10);
  World copy = run.world;
  for (int k = 0; k < 60; ++k) {
    run.world.step();
    copy.step();
  }
  CHECK(scenes::state_hash(copy) == scenes::state_hash(run.world));
}

// Every point of a manifold carries the same normal, bit for bit (Manifold's contract): the soft
// step's lanes read one normal per manifold for all its points, and give the scalar sweep's
// state only while this holds. A crowded random pile of boxes and balls on planes, with its
// manifolds as clipped, reduced to 4 points and recycled from the step before, stepped under
// the soft step until it has recycled manifolds.
TEST_CASE("every point of a manifold has its first point's normal, bit for bit", "[collision]") {
  const bool reduce = GENERATE(false, true);
  WorldDef def;
  def.push = PushMode::soft;
  def.contact_margin = 0.02;
  def.contact_recycle_distance = 0.05;
  def.manifold_points = reduce ? ManifoldPoints::four : ManifoldPoints::all;
  World world(def);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto add = [&](const Shape& shape, bool is_static, const Vec3& at) {
    add_turned(world, random, shape, is_static, at);
  };
  add(Shape::plane(Vec3::UnitY(), 0.0), true, Vec3::Zero());
  add(Shape::plane(Vec3(1.0, 1.0, 0.0), -3.0), true, Vec3::Zero());
  for (int i = 0; i < 150; ++i) {
    const Vec3 at(3.0 * unit(random) - 1.5, 0.3 + 4.0 * unit(random), 3.0 * unit(random) - 1.5);
    const double size = 0.1 + 0.3 * unit(random);
    if (i % 3 == 0) {
      add(Shape::sphere(size), false, at);
    } else {
      add(Shape::box(Vec3(size, 0.6 * size + 0.05, 0.8 * size)), false, at);
    }
  }
  std::int64_t points = 0;
  for (int step = 0; step < 90; ++step) {
    world.step();
    for (const Manifold& m : world.manifolds()) {
      for (int i = 1; i < m.count; ++i) {
        INFO("step " << step << ", bodies " << m.body_a << " and " << m.body_b << ", point " << i);
        const Vec3& n = m.contacts[static_cast<std::size_t>(i)].normal;
        REQUIRE((n.array() == m.contacts[0].normal.array()).all());
        ++points;
      }
    }
  }
  CHECK(points > 1000);  // the pile has manifolds of several points to check
  CHECK(world.counters().recycled > 0);  // and recycled ones among them (over all the steps)
}

// World::deepest_contact is counted while the collide stage makes the manifolds, on each thread
// its own share: it must equal the largest depth read back from every contact of manifolds(),
// exactly (a maximum does not depend on the order). A random pile of boxes and balls with a
// speculative margin (negative depths among the positive ones), recycled and reduced manifolds,
// on one to three threads.
TEST_CASE("the world's deepest contact is the largest depth among its manifolds' contacts",
          "[collision]") {
  const int threads = GENERATE(1, 2, 3);
  WorldDef def;
  def.push = PushMode::soft;
  def.contact_margin = 0.02;
  def.contact_recycle_distance = 0.05;
  def.manifold_points = ManifoldPoints::four;
  def.threads = threads;
  World world(def);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  world.add_body(BodyDef{.shape = Shape::plane(Vec3::UnitY(), 0.0), .is_static = true});
  for (int i = 0; i < 300; ++i) {
    const Vec3 at(4.0 * unit(random) - 2.0, 0.2 + 6.0 * unit(random), 4.0 * unit(random) - 2.0);
    const double size = 0.1 + 0.3 * unit(random);
    add_turned(world, random, i % 3 == 0 ? Shape::sphere(size) : Shape::box(Vec3::Constant(size)), false, at);
  }
  CHECK(world.deepest_contact() == 0.0);  // before the first step: no manifolds
  int overlapping_steps = 0;
  for (int step = 0; step < 90; ++step) {
    world.step();
    double deepest = 0.0;
    for (const Manifold& m : world.manifolds()) {
      for (int i = 0; i < m.count; ++i) deepest = std::max(deepest, m.contacts[static_cast<std::size_t>(i)].depth);
    }
    INFO("step " << step << ", " << threads << " threads");
    REQUIRE(world.deepest_contact() == deepest);
    overlapping_steps += deepest > 0.0 ? 1 : 0;
  }
  CHECK(overlapping_steps > 45);  // the pile overlaps: the check compares positive depths
  CHECK(world.counters().recycled > 0);
  const World copy = world;
  CHECK(copy.deepest_contact() == world.deepest_contact());
}
