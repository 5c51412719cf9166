#pragma once
// A push method: how a step corrects the constraint error (overlaps, rod stretch) and sets the
// stored momenta. It is the solve and integrate stages of World::step (world.h), after the rows
// are built and prepared; each method is one file in this folder with its derivation and
// sources on top, made through its row of the push parameter's table (parameters.cpp,
// PushTraits), which also says whether World::step prepares A lambda = b for it.

#include "../step_context.h"

#include "cps/constraint.h"
#include "cps/parameters.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace cps {

/// One way of correcting the constraint error. An object keeps its own buffers from step to step
/// (nothing of a step's physics outlives it except through the warm-start cache).
class PushMethod {
 public:
  virtual ~PushMethod() = default;

  /// Adjusts how the rows are built for this method (Sec. 5), before the build stage. The paper's
  /// methods leave `params` as they are. No errors.
  virtual void adjust_rows(const WorldDef& def, RowParams& params) const {
    (void)def;
    (void)params;
  }

  /// The collide stage's speculative distance per body (Sec. 4; m, >= 0, finite): a pair (a, b)
  /// is tested with margin def.contact_margin + margins[a] + margins[b]. Returns false (the
  /// paper's methods) to test every pair with def.contact_margin alone; when it returns true,
  /// `margins` holds one value per body. No errors.
  virtual bool contact_margins(const WorldDef& def, const std::vector<Body>& bodies,
                               std::vector<double>& margins) const {
    (void)def;
    (void)bodies;
    (void)margins;
    return false;
  }

  /// How the warm-start cache turns last step's lambdas into this step's initial guesses
  /// (warm_start.h) under the world's parameters `def`; the paper's methods take the sustained
  /// rule. No errors.
  virtual WarmStartRule warm_start_rule(const WorldDef& def) const {
    (void)def;
    return WarmStartRule::sustained;
  }

  /// Whether step() reads the contact and friction rows of ctx (Sec. 5.3, 5.4) under `def`; the
  /// paper's methods do. When false, World::build_rows leaves them to be written when the world's
  /// rows are asked for (World::rows), and step() must read no more of them than their count
  /// (the rods' rows are written all the same). No errors.
  virtual bool reads_contact_rows(const WorldDef& def) const {
    (void)def;
    return true;
  }

  /// Writes ctx.lambda (c, N) of the step just made, for a method whose step() left it to be
  /// written when asked for (ctx.lambda_pending), from what the method kept of that step; the
  /// paper's methods write it in step(). Called at most once after a step, before the next, on
  /// the calling thread. No errors.
  virtual void write_lambda(StepContext& /*ctx*/) const {}

  /// The solve and integrate stages: solves with ctx's rows and prepared solver, leaves the
  /// step's lambda (and lambda_second, or clears it) in ctx, stores the warm start, and moves the
  /// bodies over ctx.def->dt. No errors.
  virtual void step(StepContext& ctx) = 0;
};

/// The contact points of `manifolds` (count).
inline std::size_t contact_point_count(const std::vector<Manifold>& manifolds) {
  std::size_t n = 0;
  for (const Manifold& m : manifolds) n += static_cast<std::size_t>(m.count);
  return n;
}

/// Calls visit(m, c, a, b, Ra_t, Rb_t) for every contact point c of every manifold m, in the
/// order of the contact rows (World::build_rows), with its bodies a and b and the transposes of
/// their rotation matrices (world to body frame), for methods that follow a contact point in
/// the frames of its bodies through the step. No errors.
template <class Visit>
void for_each_contact_point(const std::vector<Manifold>& manifolds, const std::vector<Body>& bodies,
                            Visit&& visit) {
  for (const Manifold& m : manifolds) {
    const Body& a = bodies[static_cast<std::size_t>(m.body_a)];
    const Body& b = bodies[static_cast<std::size_t>(m.body_b)];
    const Mat3 Ra_t = a.rotation().transpose();
    const Mat3 Rb_t = b.rotation().transpose();
    for (int i = 0; i < m.count; ++i) {
      visit(m, m.contacts[static_cast<std::size_t>(i)], a, b, Ra_t, Rb_t);
    }
  }
}

}  // namespace cps
