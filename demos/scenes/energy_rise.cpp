// The energy watch: the largest rise of KE + PE above the start, against the energy scale of
// EnergyRise (energy_rise.h), and the warning that names the push method and the fix.
#include "energy_rise.h"

#include "divergence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cps::scenes {

double EnergyRise::rise_J() const { return std::max(0.0, max_J - start_J); }

double EnergyRise::fraction() const {
  const double rise = rise_J();
  if (!(rise > 0.0)) return 0.0;
  return scale_J > 0.0 ? rise / scale_J : kInfinity;
}

bool EnergyRise::warns() const { return fraction() > kEnergyRiseWarnFraction || thrown.has_value(); }

MechanicalEnergy mechanical_energy(const World& world) {
  const Vec3& g = world.def().gravity;
  MechanicalEnergy e;
  for (const Body& b : world.bodies()) {
    if (b.is_static()) continue;
    e.kinetic_J += b.kinetic_energy();
    e.potential_J -= b.mass * g.dot(b.x);
  }
  return e;
}

void EnergyRiseTracker::observe(const World& world) {
  const auto& bodies = world.bodies();
  const Vec3& g = world.def().gravity;
  const double g_norm = g.norm();
  const Vec3 up = g_norm > 0.0 ? Vec3(-g / g_norm) : Vec3::Zero();
  const MechanicalEnergy now = mechanical_energy(world);
  const double kinetic = now.kinetic_J;
  const double energy = now.total_J();
  if (!std::isfinite(energy)) {
    rise_.nonfinite = true;
    return;
  }
  if (!started_) {
    started_ = true;
    g_ = g_norm;
    start_kinetic_J_ = kinetic;
    rise_.start_J = energy;
    rise_.max_J = energy;
    rise_.max_time_s = world.time();
    mass_.assign(bodies.size(), 0.0);
    start_h_.assign(bodies.size(), 0.0);
    top_h_ = -kInfinity;  // no movable body: no fall, the limit is the start speed
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const Body& b = bodies[i];
      if (b.is_static()) continue;
      mass_[i] = b.mass;
      start_h_[i] = up.dot(b.x);
      const double r = b.shape.kind == ShapeKind::sphere ? b.shape.radius : b.shape.half_extents.norm();
      size_J_ += b.mass * g_norm * r;
      start_speed_mps_ = std::max(start_speed_mps_, b.velocity().norm());
      top_h_ = std::max(top_h_, start_h_[i] + r);
    }
    peaks_.emplace_back(world.time(), energy);
    lowest_h_ = start_h_;
    previous_x_.assign(bodies.size(), Vec3::Zero());
    previous_time_s_ = world.time();
  }
  // Bodies are only ever added before a run starts; a world that grew is measured by its first
  // bodies.
  const std::size_t n = std::min(bodies.size(), lowest_h_.size());
  if (world.time() > previous_time_s_) {
    // The lift of the positions' own correction: x2 - x1 - v2 dt against gravity (0 for the
    // Baumgarte push, whose positions move with the stored momenta).
    const double dt = world.def().dt;
    for (std::size_t i = 0; i < n; ++i) {
      if (mass_[i] == 0.0) continue;
      const Vec3 dx_push = bodies[i].x - previous_x_[i] - bodies[i].velocity() * dt;
      rise_.lift_J += std::max(0.0, -mass_[i] * g.dot(dx_push));
    }
  }
  previous_time_s_ = world.time();
  // Rows were built (contacts or rods), without asking for the rows themselves.
  const auto& manifolds = world.manifolds();
  if (world.counters().steps > 0 &&
      (!world.distances().empty() ||
       std::any_of(manifolds.begin(), manifolds.end(), [](const Manifold& m) { return m.count > 0; }))) {
    rise_.constrained = true;
  }
  for (std::size_t i = 0; i < n; ++i) {
    previous_x_[i] = bodies[i].x;
    if (mass_[i] > 0.0) lowest_h_[i] = std::min(lowest_h_[i], up.dot(bodies[i].x));
  }
  if (energy - rise_.lift_J > rise_.max_J) {
    rise_.max_J = energy - rise_.lift_J;
    rise_.max_time_s = world.time();
    if (rise_.max_J - peaks_.back().second >= 1e-3 * size_J_) peaks_.emplace_back(world.time(), rise_.max_J);
  }
  if (!rise_.thrown) {
    // The largest restitution a contact can have: the world's, or a body's own (pair_restitution).
    double eps = world.def().restitution;
    for (const Body& b : world.bodies()) eps = pair_restitution(eps, b.restitution, eps);
    const double bounce = 1.0 + eps;
    for (std::size_t i = 0; i < n; ++i) {
      if (mass_[i] == 0.0) continue;
      const double limit = std::sqrt(1.0 + kEnergyRiseWarnFraction) * bounce *
                           (start_speed_mps_ + std::sqrt(2.0 * g_ * std::max(0.0, top_h_ - lowest_h_[i])));
      const double speed = bodies[i].velocity().norm();
      if (speed > limit) {
        rise_.thrown = EnergyRise::Thrown{static_cast<int>(i), mass_[i], speed, limit, world.time()};
        break;
      }
    }
  }
}

EnergyRise EnergyRiseTracker::result() const {
  EnergyRise out = rise_;
  double available = start_kinetic_J_;
  for (std::size_t i = 0; i < mass_.size(); ++i) available += mass_[i] * g_ * (start_h_[i] - lowest_h_[i]);
  out.scale_J = std::max(available, size_J_);
  // The first kept peak past the threshold; the last peak is the maximum itself.
  const double threshold = rise_.start_J + kEnergyRiseWarnFraction * out.scale_J;
  for (const auto& [t, e] : peaks_) {
    if (e > threshold) {
      out.warn_time_s = t;
      break;
    }
  }
  if (std::isnan(out.warn_time_s) && out.max_J > threshold) out.warn_time_s = out.max_time_s;
  return out;
}

namespace {

// Forwards to the scene's own metrics and feeds the tracker.
class EnergyRiseMetrics final : public Metrics {
 public:
  EnergyRiseMetrics(std::unique_ptr<Metrics> inner, std::shared_ptr<EnergyRiseTracker> tracker)
      : inner_(std::move(inner)), tracker_(std::move(tracker)) {}
  void observe(const World& world) override {
    inner_->observe(world);
    tracker_->observe(world);
  }
  nlohmann::json report() const override { return inner_->report(); }

 private:
  std::unique_ptr<Metrics> inner_;
  std::shared_ptr<EnergyRiseTracker> tracker_;
};

// What to try instead of `push`, with why, for the warning; `constrained`: EnergyRise's.
std::string fix_for(PushMode push, bool constrained) {
  if (!constrained) {
    return "no contact or rod acted, so no push did: the rise is the integrator's (no gyroscopic "
           "term: a body spinning about an axis that is not a principal one changes its kinetic "
           "energy at constant angular momentum, docs/conventions.md); no --push changes it";
  }
  const PushTraits& traits = push_traits(push);
  if (traits.push_in_momenta) {
    return std::string(traits.energy_rise_cause) +
           "; try --push split (Sec. 8.1: the push moves the positions, the momenta come from a "
           "solve without it; \"push\": \"split\" in a scene file's \"world\")";
  }
  return "this push keeps itself out of the momenta, so the rise comes from the solve: try a "
         "smaller --dt or more --iterations";
}

}  // namespace

std::shared_ptr<const EnergyRiseTracker> watch_energy_rise(Run& run) {
  auto tracker = std::make_shared<EnergyRiseTracker>();
  tracker->observe(run.world);
  run.metrics = std::make_unique<EnergyRiseMetrics>(std::move(run.metrics), tracker);
  return tracker;
}

std::string energy_rise_warning(std::string_view what, const WorldDef& def, const EnergyRise& rise) {
  if (!rise.warns()) return {};
  const std::string fix = "the push is --push " + std::string(name_of(def.push)) + ": " +
                          fix_for(def.push, rise.constrained);
  char text[512];
  std::string out(what);
  if (rise.fraction() > kEnergyRiseWarnFraction) {
    char share[64];
    if (std::isfinite(rise.fraction())) {
      std::snprintf(share, sizeof share, "%.0f %%", 100.0 * rise.fraction());
    } else {
      std::snprintf(share, sizeof share, "from nothing");
    }
    std::snprintf(text, sizeof text,
                  ": the energy (kinetic + potential) rose %s above its start with nothing driving "
                  "the scene, more than the %.0f %% that warns (it passed that at t = %.3g s; the "
                  "largest, +%.3g J, at t = %.3g s; 100 %% = %.3g J, the start's energy above the "
                  "bodies' lowest points or their size, see docs/findings.md)",
                  share, 100.0 * kEnergyRiseWarnFraction, rise.warn_time_s, rise.rise_J(),
                  rise.max_time_s, rise.scale_J);
    out += text;
  }
  if (rise.thrown) {
    const EnergyRise::Thrown& t = *rise.thrown;
    std::snprintf(text, sizeof text,
                  "%s body %d (%.3g kg) was thrown at %.3g m/s at t = %.3g s, faster than anything "
                  "in the scene could make it without a gain (%.3g m/s: a fall from the scene's "
                  "highest point plus its fastest start, times 1 + restitution, with %.0f %% more kinetic "
                  "energy than that allowed)",
                  out.size() > what.size() ? "; and" : ":", t.body, t.mass_kg, t.speed_mps,
                  t.time_s, t.limit_mps, 100.0 * kEnergyRiseWarnFraction);
    out += text;
  }
  return out + "; " + fix;
}

std::vector<RunWarning> run_warnings(std::string_view scene, std::string_view label, const Run& run,
                                     const EnergyRiseTracker& tracker) {
  const std::string_view first_line = label.substr(0, label.find('\n'));
  std::string what(scene);
  if (!first_line.empty()) what += " (" + std::string(first_line) + ")";
  std::vector<RunWarning> out;
  if (const std::optional<Divergence> d = run.divergence ? run.divergence->found() : std::nullopt) {
    char at[64];
    std::snprintf(at, sizeof at, "%.4g", d->at_s);
    out.push_back({"divergence", divergence_warning(what, *d),
                   what + ": the run diverged at t = " + at + " s", "docs/commands.md#simulate"});
  }
  const EnergyRise rise = tracker.result();
  if (std::string text = energy_rise_warning(what, run.world.def(), rise); !text.empty()) {
    char brief[160];
    if (rise.fraction() > kEnergyRiseWarnFraction && std::isfinite(rise.fraction())) {
      std::snprintf(brief, sizeof brief, ": the energy rose %.0f %% above its start with nothing "
                    "driving the scene", 100.0 * rise.fraction());
    } else if (rise.fraction() > kEnergyRiseWarnFraction) {
      std::snprintf(brief, sizeof brief, ": the energy rose from nothing with nothing driving the scene");
    } else {
      std::snprintf(brief, sizeof brief, ": a body was thrown faster than the scene allows");
    }
    out.push_back({"energy_rise", std::move(text), what + brief,
                   "docs/findings.md#energy-that-rises-with-nothing-driving-it"});
  }
  return out;
}

}  // namespace cps::scenes
