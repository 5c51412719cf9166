// The system of Sec. 6 and projected Gauss-Seidel (Sec. 7).
#include "solver.h"
#include "cps/world.h"

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <random>

using namespace cps;

namespace {

// A = B B^T + c I: symmetric positive definite with a dominant enough diagonal for PGS.
SparseRowMatrix random_spd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd B(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) B(i, j) = u(rng);
  }
  const Eigen::MatrixXd A = B * B.transpose() + n * Eigen::MatrixXd::Identity(n, n);
  return A.sparseView();
}

Eigen::VectorXd random_vector(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

}  // namespace

TEST_CASE("PGS with no active bounds agrees with a direct solve", "[solver]") {
  for (const unsigned seed : {1u, 2u, 3u}) {
    const int n = 12;
    const SparseRowMatrix A = random_spd(n, seed);
    const Eigen::VectorXd b = random_vector(n, seed + 100);
    const Eigen::VectorXd lo = Eigen::VectorXd::Constant(n, -kInfinity);
    const Eigen::VectorXd hi = Eigen::VectorXd::Constant(n, kInfinity);
    const Eigen::VectorXd direct = Eigen::MatrixXd(A).ldlt().solve(b);
    const Eigen::VectorXd lambda = solve_pgs(A, b, lo, hi, 200);
    CHECK((lambda - direct).norm() <= 1e-10 * direct.norm());
    // A handful of sweeps does not converge yet: the check above measures convergence.
    CHECK((solve_pgs(A, b, lo, hi, 2) - direct).norm() > 1e-6 * direct.norm());
  }
}

TEST_CASE("PGS respects the bounds and meets the LCP conditions at convergence", "[solver]") {
  const int n = 12;
  const SparseRowMatrix A = random_spd(n, 7);
  const Eigen::VectorXd b = random_vector(n, 8);
  const Eigen::VectorXd lo = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd hi = Eigen::VectorXd::Constant(n, 0.2);
  const Eigen::VectorXd lambda = solve_pgs(A, b, lo, hi, 500);
  const Eigen::VectorXd w = A * lambda - b;  // residual of A lambda = b
  int at_lower = 0;
  int at_upper = 0;
  for (int i = 0; i < n; ++i) {
    REQUIRE(lambda[i] >= lo[i]);
    REQUIRE(lambda[i] <= hi[i]);
    if (lambda[i] == lo[i]) {
      ++at_lower;
      CHECK(w[i] >= -1e-9);  // pushing it lower would be needed to reach b: allowed only at c_min
    } else if (lambda[i] == hi[i]) {
      ++at_upper;
      CHECK(w[i] <= 1e-9);
    } else {
      CHECK(std::abs(w[i]) <= 1e-9);
    }
  }
  // The case exercises both bounds.
  CHECK(at_lower > 0);
  CHECK(at_upper > 0);
}

TEST_CASE("solve_pgs rejects mismatched sizes", "[solver]") {
  const SparseRowMatrix A = random_spd(3, 1);
  CHECK_THROWS_AS(solve_pgs(A, Eigen::VectorXd::Zero(4), Eigen::VectorXd::Zero(4),
                            Eigen::VectorXd::Zero(4), 5),
                  std::invalid_argument);
}

TEST_CASE("an overlap opens at the push factor's velocity beta d / dt", "[solver]") {
  // No gravity, no friction: box b overlaps box a by d = 0.1 m. With the sign convention of
  // docs/conventions.md the contact rows ask for a separating velocity of beta d / dt along +y, which the
  // converged solve delivers exactly, shared by the two equal masses.
  WorldDef def;
  def.gravity = Vec3::Zero();
  def.friction = 0.0;
  def.beta = 0.2;
  def.iterations = 200;
  World world(def);
  BodyDef box;
  box.shape = Shape::box(Vec3::Ones());
  box.position = Vec3(0, 0, 0);
  world.add_body(box);
  box.position = Vec3(0, 1.9, 0);
  world.add_body(box);
  world.step();
  const double target = def.beta * 0.1 / def.dt;  // m/s
  const Vec3 rel = world.body(1).velocity() - world.body(0).velocity();
  CHECK(rel.y() == Approx(target).epsilon(1e-6));
  CHECK(rel.x() == Approx(0.0).margin(1e-9));
  CHECK(world.body(1).velocity().y() > 0.0);  // b moves away from a, a away from b
  CHECK(world.body(0).velocity().y() < 0.0);
  for (double lambda : world.lambda()) CHECK(lambda >= 0.0);  // contacts only push
}

TEST_CASE("assemble_system builds A = J M^-1 J^T and b of Eq. 6.2.9", "[solver]") {
  // One box resting on the ground, checked entry by entry against dense algebra.
  World world;
  world.add_body({Shape::plane(Vec3::UnitY(), 0.0), true});
  BodyDef box;
  box.shape = Shape::box(Vec3(0.5, 0.5, 0.5));
  box.position = Vec3(0.0, 0.45, 0.0);
  box.velocity = Vec3(0.3, -1.0, 0.0);
  box.angular_velocity = Vec3(0.0, 0.5, 0.2);
  world.add_body(box);
  std::vector<Manifold> manifolds(1);
  manifolds[0].body_a = 0;
  manifolds[0].body_b = 1;
  REQUIRE(collide(world.body(0), world.body(1), manifolds[0]) == 4);
  std::vector<ConstraintRow> rows;
  append_contact_rows(manifolds[0], world.bodies(), {0.2, 1.0 / 60.0, 0.5, Vec3(0, -10, 0)}, rows);
  REQUIRE(rows.size() == 12);
  const Eigen::VectorXd v1 = system_velocity(world.bodies());
  const Eigen::VectorXd f = gravity_forces(world.bodies(), Vec3(0, -10, 0));
  const double dt = 1.0 / 60.0;
  const System s = assemble_system(rows, world.bodies(), v1, f, dt, TargetTerms::push_and_bias);
  const Eigen::MatrixXd J(s.J);
  const Eigen::MatrixXd M_inv(s.M_inv);
  CHECK((Eigen::MatrixXd(s.A) - J * M_inv * J.transpose()).norm() <= 1e-12);
  Eigen::VectorXd v(12);
  for (int r = 0; r < 12; ++r) v[r] = rows[static_cast<std::size_t>(r)].push;
  const Eigen::VectorXd b = v / dt - J * (v1 / dt + M_inv * f);
  CHECK((s.b - b).norm() <= 1e-9 * b.norm());
  // J v1 is the rate at which the contact point of the box leaves the ground along n = +y.
  const Body& b1 = world.body(1);
  const Vec3 r_b = manifolds[0].contacts[0].point - b1.x;
  const double rate = Vec3::UnitY().dot(b1.velocity() + b1.angular_velocity().cross(r_b));
  CHECK((J * v1)[0] == Approx(rate).margin(1e-12));
}

TEST_CASE("the natural-map LCP residual is zero at the solution and only there", "[solver]") {
  const int n = 12;
  const SparseRowMatrix A = random_spd(n, 11);
  const Eigen::VectorXd b = random_vector(n, 12);
  RowLimits limits;
  limits.c_min = Eigen::VectorXd::Zero(n);
  limits.c_max = Eigen::VectorXd::Constant(n, 0.3);
  const Eigen::VectorXd converged = solve_pgs(A, b, limits.c_min, limits.c_max, 500);
  CHECK(lcp_residual(A, b, limits, FrictionModel::fixed, converged).maxCoeff() < 1e-9);
  const Eigen::VectorXd early = solve_pgs(A, b, limits.c_min, limits.c_max, 1);
  CHECK(lcp_residual(A, b, limits, FrictionModel::fixed, early).maxCoeff() > 1e-3);
  // Unbounded rows: the residual is |A lambda - b|_j / A_jj.
  limits.c_min.setConstant(-kInfinity);
  limits.c_max.setConstant(kInfinity);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd r = lcp_residual(A, b, limits, FrictionModel::fixed, zero);
  for (int j = 0; j < n; ++j) CHECK(r[j] == Approx(std::abs(b[j]) / A.coeff(j, j)));
}
