#pragma once
// The divergence watch of every run (make_run installs it): when a run stopped meaning anything,
// and the metrics measured up to it. A run has diverged when a movable body's position,
// orientation or velocity is not finite, or when, for kDivergedSteps steps in a row, a contact is
// deeper than the smallest full size of a movable body it touches (a box's shortest edge, a
// ball's diameter): the body has been driven through what it rests on, as a stack stepped at
// dt = 1 s sinks into the ground. One such step alone is a fast body arriving (a 50 m/s ball
// lands deeper than its size in one step and is pushed out in the next).

#include "scene.h"

#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace cps::scenes {

/// Steps in a row with a contact past a body's size that make a divergence (count).
inline constexpr int kDivergedSteps = 3;

/// When and why a run diverged.
struct Divergence {
  double at_s = 0.0;  ///< s: the world's time after the first step that showed it
  std::string why;    ///< what was seen, with the body and the numbers
  bool nonfinite = false;  ///< a state was not finite (else a contact past a body's size)
};

/// What one step shows, if anything: a state that is not finite, or a contact past a body's
/// size (see the file comment; one step of the latter is not yet a divergence). No errors.
std::optional<Divergence> divergence_sign(const World& world);

/// The divergence of one run so far (see the file comment), fed after every step.
class DivergenceWatch {
 public:
  /// Feeds the world after a step (or as built). No errors.
  void observe(const World& world);
  /// The divergence, once found: its time is the first step that showed it.
  const std::optional<Divergence>& found() const { return found_; }

 private:
  std::optional<Divergence> streak_;  // the first sign of the current run of them
  int steps_ = 0;                     // steps in that run
  std::optional<Divergence> found_;
};

/// Wraps `inner` so that every step also feeds `watch`, and `inner` observes the run only up to
/// its divergence and is told when it began (Metrics::diverged_since): an event after that (a
/// slide-off, a body leaving its place) is not measured, values at the end are. The report adds
/// "diverged" (bool), "diverged_at_s" (s, or null) and "diverged_why" (text, or null) to the
/// inner report's keys.
std::unique_ptr<Metrics> watch_divergence(std::unique_ptr<Metrics> inner,
                                          std::shared_ptr<DivergenceWatch> watch);

/// The one-line warning for a run that diverged, naming `what` (the scene and its variant).
/// No errors.
std::string divergence_warning(std::string_view what, const Divergence& d);

}  // namespace cps::scenes
