// The divergence watch (see divergence.h).
#include "divergence.h"

#include <algorithm>
#include <cstdio>
#include <limits>

namespace cps::scenes {
namespace {

// The smallest full size of a movable body (m): a box's shortest edge, a ball's diameter;
// +inf for a static body (a plane or a fixed box has no side to pass through).
double smallest_size(const Body& b) {
  if (b.is_static()) return std::numeric_limits<double>::infinity();
  return b.shape.kind == ShapeKind::sphere ? 2.0 * b.shape.radius : 2.0 * b.shape.half_extents.minCoeff();
}

class DivergenceMetrics final : public Metrics {
 public:
  DivergenceMetrics(std::unique_ptr<Metrics> inner, std::shared_ptr<DivergenceWatch> watch)
      : inner_(std::move(inner)), watch_(std::move(watch)) {}
  void observe(const World& world) override {
    if (watch_->found()) return;
    watch_->observe(world);
    if (watch_->found()) {
      inner_->diverged_since(watch_->found()->at_s);
    } else {
      inner_->observe(world);
    }
  }
  nlohmann::json report() const override {
    nlohmann::json j = inner_->report();
    const std::optional<Divergence>& d = watch_->found();
    j["diverged"] = d.has_value();
    j["diverged_at_s"] = d ? nlohmann::json(d->at_s) : nlohmann::json();
    j["diverged_why"] = d ? nlohmann::json(d->why) : nlohmann::json();
    return j;
  }

 private:
  std::unique_ptr<Metrics> inner_;
  std::shared_ptr<DivergenceWatch> watch_;
};

}  // namespace

std::optional<Divergence> divergence_sign(const World& world) {
  const std::vector<Body>& bodies = world.bodies();
  char why[200];
  double smallest = std::numeric_limits<double>::infinity();  // of every movable body (m)
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    if (b.is_static()) continue;
    if (!b.x.allFinite() || !b.o.coeffs().allFinite() || !b.velocity().allFinite() ||
        !b.angular_velocity().allFinite()) {
      std::snprintf(why, sizeof why, "body %zu's state is not finite", i);
      return Divergence{world.time(), why, true};
    }
    smallest = std::min(smallest, smallest_size(b));
  }
  // A contact deeper than its smaller body is deeper than the smallest movable body: when none
  // is, the pass below (which reads both bodies of every manifold) finds nothing.
  if (!(deepest_contact(world) > smallest)) return std::nullopt;
  for (const Manifold& m : world.manifolds()) {
    const double size = std::min(smallest_size(bodies[static_cast<std::size_t>(m.body_a)]),
                                 smallest_size(bodies[static_cast<std::size_t>(m.body_b)]));
    for (int k = 0; k < m.count; ++k) {
      const double depth = m.contacts[static_cast<std::size_t>(k)].depth;
      if (depth > size) {
        std::snprintf(why, sizeof why,
                      "a contact between bodies %d and %d is %.3g m deep, past the %.3g m of the "
                      "smaller body, and stays past it %d steps: it has been driven through",
                      m.body_a, m.body_b, depth, size, kDivergedSteps);
        return Divergence{world.time(), why, false};
      }
    }
  }
  return std::nullopt;
}

void DivergenceWatch::observe(const World& world) {
  if (found_) return;
  const std::optional<Divergence> sign = divergence_sign(world);
  if (!sign) {
    streak_.reset();
    steps_ = 0;
    return;
  }
  if (!streak_) streak_ = sign;
  ++steps_;
  // A state that is not finite diverges at once; a deep contact after kDivergedSteps steps.
  if (sign->nonfinite || steps_ >= kDivergedSteps) {
    found_ = Divergence{streak_->at_s, sign->nonfinite ? sign->why : streak_->why, sign->nonfinite};
  }
}

std::unique_ptr<Metrics> watch_divergence(std::unique_ptr<Metrics> inner,
                                          std::shared_ptr<DivergenceWatch> watch) {
  return std::make_unique<DivergenceMetrics>(std::move(inner), std::move(watch));
}

std::string divergence_warning(std::string_view what, const Divergence& d) {
  char at[64];
  std::snprintf(at, sizeof at, "%.4g", d.at_s);
  return std::string(what) + ": the run diverged at t = " + at + " s (" + d.why +
         "); the metrics measure it up to then: try a smaller --dt, more --iterations or another "
         "--push";
}

}  // namespace cps::scenes
