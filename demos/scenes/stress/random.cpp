// random: a random pile from a seed (populate_random in stress.h), here seed 1. Boxes and balls
// of 0.05 to 5 m and 0.01 to 1000 kg thrown at up to 50 m/s, possibly overlapping each other and
// the ground: mass ratios up to 1e5, deep overlaps, tunnelling. The test runs many seeds.
#include "stress/stress.h"

#include <cmath>
#include <numbers>
#include <random>

namespace cps::scenes {
namespace {

constexpr int kMinBodies = 4;
constexpr int kMaxBodies = 12;
constexpr double kMinSize = 0.05;    // m: box edge or ball diameter
constexpr double kMaxSize = 5.0;     // m
constexpr double kMinMass = 0.01;    // kg
constexpr double kMaxMass = 1000.0;  // kg
constexpr double kHalfWidth = 4.0;   // m: centres in [-4, 4] in x and z
constexpr double kMaxHeight = 8.0;   // m: centres in [0, 8] in y
constexpr double kMaxSpeed = 50.0;   // m/s

// The sampling is written out so that a seed means the same scene with every standard library
// (std::uniform_real_distribution and friends are implementation-defined).
class Sampler {
 public:
  explicit Sampler(std::uint64_t seed) : rng_(seed) {}
  // Uniform in [0, 1): the top 53 bits of one draw.
  double unit() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  double log_uniform(double lo, double hi) { return lo * std::exp(unit() * std::log(hi / lo)); }
  // Uniform on the unit sphere (Archimedes: z is uniform in [-1, 1]).
  Vec3 direction() {
    const double z = 2.0 * unit() - 1.0;
    const double phi = 2.0 * std::numbers::pi * unit();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
  }
  // Uniform on the rotations (Shoemake, "Uniform random rotations", Graphics Gems III, 1992).
  Quat rotation() {
    const double u1 = unit();
    const double a = 2.0 * std::numbers::pi * unit();
    const double b = 2.0 * std::numbers::pi * unit();
    const double s1 = std::sqrt(1.0 - u1);
    const double s2 = std::sqrt(u1);
    return Quat(s2 * std::cos(b), s1 * std::sin(a), s1 * std::cos(a), s2 * std::sin(b)).normalized();
  }

 private:
  std::mt19937_64 rng_;
};

class RandomMetrics final : public EnergyMetrics {
 public:
  void observe(const World& world) override {
    EnergyMetrics::observe(world);
    if (energy_.nonfinite()) return;
    for (const Body& b : world.bodies()) {
      if (!b.is_static()) max_speed_ = std::max(max_speed_, b.velocity().norm());
    }
  }
  nlohmann::json report() const override {
    nlohmann::json j = EnergyMetrics::report();
    j["bodies"] = world_ ? static_cast<int>(world_->bodies().size()) - 1 : 0;
    j["max_speed_mps"] = max_speed_;
    return j;
  }

 private:
  double max_speed_ = 0.0;
};

}  // namespace

void populate_random(World& world, std::uint64_t seed) {
  Sampler s(seed);
  add_ground(world);
  const int count = kMinBodies + static_cast<int>(s.unit() * (kMaxBodies - kMinBodies + 1));
  for (int i = 0; i < count; ++i) {
    BodyDef body;
    if (s.unit() < 0.5) {
      Vec3 half;
      for (int k = 0; k < 3; ++k) half[k] = 0.5 * s.log_uniform(kMinSize, kMaxSize);
      body.shape = Shape::box(half);
    } else {
      body.shape = Shape::sphere(0.5 * s.log_uniform(kMinSize, kMaxSize));
    }
    body.mass = s.log_uniform(kMinMass, kMaxMass);
    const double x = s.uniform(-kHalfWidth, kHalfWidth);
    const double y = s.uniform(0.0, kMaxHeight);
    const double z = s.uniform(-kHalfWidth, kHalfWidth);
    body.position = Vec3(x, y, z);
    body.orientation = s.rotation();
    const Vec3 dir = s.direction();
    body.velocity = s.uniform(0.0, kMaxSpeed) * dir;
    world.add_body(body);
  }
}

void populate_random_seed_1(World& world) { populate_random(world, 1); }

std::unique_ptr<Metrics> make_random_metrics(const World& world) {
  return observed<RandomMetrics>(world);
}

}  // namespace cps::scenes
