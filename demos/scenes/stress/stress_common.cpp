// Measurements shared by the stress scenes: total energy, finiteness, the push-work bound.
#include "stress/stress.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace cps::scenes {

double total_energy(const World& world) {
  const Vec3& g = world.def().gravity;
  double e = 0.0;
  for (const Body& b : world.bodies()) {
    if (b.is_static()) continue;
    e += b.kinetic_energy() - b.mass * g.dot(b.x);
  }
  return e;
}

bool all_finite(const World& world) {
  for (const Body& b : world.bodies()) {
    if (!b.x.allFinite() || !b.o.coeffs().allFinite() || !b.p.allFinite() || !b.l.allFinite()) {
      return false;
    }
  }
  return true;
}

void EnergyTracker::observe(const World& world) {
  if (!all_finite(world)) {
    nonfinite_ = true;
    return;  // nothing below means anything once a state is not finite
  }
  const auto& bodies = world.bodies();
  const double dt = world.def().dt;
  const Vec3& g = world.def().gravity;
  if (previous_.size() == bodies.size() && world.counters().steps > 0) {
    double work = 0.0;
    if (push_traits(world.def().push).push_in_rows) {
      // dt sum_r max(0, lambda_r t_r) over the rows of the step just taken.
      const auto& rows = world.rows();
      const std::vector<double>& lambda = world.lambda();
      for (std::size_t r = 0; r < rows.size() && r < lambda.size(); ++r) {
        work += dt * std::max(0.0, lambda[r] * (rows[r].push + rows[r].bias));
      }
    } else {
      // The push displacement x2 - x1 - v2 dt against gravity.
      for (std::size_t i = 0; i < bodies.size(); ++i) {
        const Body& b = bodies[i];
        if (b.is_static()) continue;
        const Vec3 dx_push = b.x - previous_[i].x - b.velocity() * dt;
        work += std::max(0.0, -b.mass * g.dot(dx_push));
      }
    }
    push_work_ += work;
    double rotation = 0.0;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const Body& b = bodies[i];
      if (b.is_static()) continue;
      const Mat3 R1 = previous_[i].o.toRotationMatrix();
      const Mat3 inv_i1 = R1 * b.inv_inertia_body * R1.transpose();
      rotation += std::max(0.0, 0.5 * b.l.dot((b.inv_inertia_world() - inv_i1) * b.l));
    }
    rotation_drift_ += rotation;
    max_step_excess_ = std::max(max_step_excess_, total_energy(world) - current_ - work - rotation);
  }
  previous_.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) previous_[i] = {bodies[i].x, bodies[i].o};

  current_ = total_energy(world);
  if (!initial_) initial_ = current_;
  max_ = std::max(max_, current_);
  max_gain_ = std::max(max_gain_, current_ - *initial_);
  max_unaccounted_ =
      std::max(max_unaccounted_, current_ - *initial_ - push_work_ - rotation_drift_);
}

void EnergyTracker::add_to(nlohmann::json& j) const {
  j["initial_energy_J"] = initial();
  j["max_energy_J"] = max_;
  j["energy_J"] = current_;
  j["max_energy_gain_J"] = max_gain_;
  j["push_work_J"] = push_work_;
  j["rotation_drift_J"] = rotation_drift_;
  j["max_unaccounted_energy_J"] = max_unaccounted_;
  j["max_step_energy_excess_J"] = max_step_excess_;
  j["nan"] = nonfinite_;
}

void EnergyMetrics::observe(const World& world) {
  world_ = &world;
  energy_.observe(world);
  if (!energy_.nonfinite()) max_penetration_ = std::max(max_penetration_, deepest_contact(world));
}

nlohmann::json EnergyMetrics::report() const {
  nlohmann::json j = nlohmann::json::object();
  energy_.add_to(j);
  j["max_penetration_m"] = max_penetration_;
  j["final_penetration_m"] =
      world_ && !energy_.nonfinite() ? nlohmann::json(max_penetration_now(*world_)) : nlohmann::json();
  return j;
}

HardCaseWatch::HardCaseWatch(std::vector<Vec3> resting_places, double leave_m)
    : rest_(std::move(resting_places)), leave_m_(leave_m) {
  if (!(leave_m > 0.0) || !std::isfinite(leave_m)) {
    throw std::invalid_argument("HardCaseWatch: leave distance " + std::to_string(leave_m) +
                                " m; allowed: finite and > 0");
  }
}

void HardCaseWatch::observe(const World& world) {
  if (nonfinite_) return;
  if (!all_finite(world)) {
    nonfinite_ = true;  // nothing below means anything once a state is not finite
    return;
  }
  const std::vector<Body>& bodies = world.bodies();
  const Vec3& g = world.def().gravity;
  if (!start_energy_J_) {
    start_energy_J_ = total_energy(world);
    double lightest = std::numeric_limits<double>::max();
    double heaviest = 0.0;
    for (std::size_t i = 0; i < bodies.size() && i < rest_.size(); ++i) {
      if (bodies[i].is_static()) continue;
      rest_energy_J_ -= bodies[i].mass * g.dot(rest_[i]);
      lightest = std::min(lightest, bodies[i].mass);
      heaviest = std::max(heaviest, bodies[i].mass);
    }
    if (heaviest > 0.0) mass_ratio_ = heaviest / lightest;
  }
  observed_s_ = world.time();
  final_displacement_m_ = 0.0;
  for (std::size_t i = 0; i < bodies.size() && i < rest_.size(); ++i) {
    if (!bodies[i].is_static()) {
      final_displacement_m_ = std::max(final_displacement_m_, (bodies[i].x - rest_[i]).norm());
    }
  }
  const bool in_place = final_displacement_m_ <= leave_m_;
  if (in_place) {
    out_since_.reset();
    if (!in_place_since_) in_place_since_ = observed_s_;
  } else {
    in_place_since_.reset();
    if (arrival_s_ && !out_since_) out_since_ = observed_s_;
  }
  // Held for kHoldS: observed_s_ - since is a whole number of steps, up to round-off.
  const double half_step = 0.5 * world.def().dt;
  if (!arrival_s_ && in_place_since_ && observed_s_ - *in_place_since_ + half_step >= kHoldS) {
    arrival_s_ = in_place_since_;
  }
  if (arrival_s_ && !left_s_ && out_since_ && observed_s_ - *out_since_ + half_step >= kHoldS) {
    left_s_ = out_since_;
  }
  max_penetration_m_ = std::max(max_penetration_m_, deepest_contact(world));
  max_energy_J_ = std::max(max_energy_J_, total_energy(world));
  max_rod_stretch_m_ = std::max(max_rod_stretch_m_, max_rod_error(world));
}

bool HardCaseWatch::holds() const {
  return !nonfinite_ && !diverged_s_ && arrival_s_.has_value() && !left_s_ &&
         final_displacement_m_ <= leave_m_;
}

void HardCaseWatch::diverged_since(double since_s) {
  diverged_s_ = since_s;
  if (left_s_ && *left_s_ >= since_s) left_s_.reset();
  if (arrival_s_ && *arrival_s_ >= since_s) arrival_s_.reset();
}

void HardCaseWatch::add_to(nlohmann::json& j) const {
  const double reference = std::max(start_energy_J_.value_or(0.0), rest_energy_J_);
  j["leave_distance_m"] = leave_m_;
  j["arrival_s"] = arrival_s_ ? nlohmann::json(*arrival_s_) : nlohmann::json();
  j["survival_s"] = !arrival_s_ ? 0.0 : std::min(left_s_.value_or(observed_s_), diverged_s_.value_or(kInfinity));
  j["final_displacement_m"] = final_displacement_m_;
  j["max_penetration_m"] = max_penetration_m_;
  j["energy_injected_J"] = start_energy_J_ ? std::max(0.0, max_energy_J_ - reference) : 0.0;
  j["max_rod_stretch_m"] = max_rod_stretch_m_;
  j["mass_ratio"] = mass_ratio_;
  j["holds"] = holds();
  j["nan"] = nonfinite_;
}

nlohmann::json HardCaseMetrics::report() const {
  nlohmann::json j = nlohmann::json::object();
  watch_.add_to(j);
  return j;
}

std::vector<Vec3> resting_places_as_built(const World& world) {
  std::vector<Vec3> places;
  places.reserve(world.bodies().size());
  for (const Body& b : world.bodies()) places.push_back(b.x);
  return places;
}

std::vector<Vec3> resting_places_stacked(const World& world) {
  std::vector<Vec3> places = resting_places_as_built(world);
  double top = 0.0;  // m: the top of the column so far (the ground plane y = 0 at first)
  for (std::size_t i = 0; i < places.size(); ++i) {
    const Body& b = world.bodies()[i];
    if (b.is_static()) continue;
    const double half_height =
        b.shape.kind == ShapeKind::box ? b.shape.half_extents.y() : b.shape.radius;
    places[i].y() = top + half_height;
    top += 2.0 * half_height;
  }
  return places;
}

}  // namespace cps::scenes
