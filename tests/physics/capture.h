#pragma once
// The system a built-in scene's world solves at a given step, captured through its solve
// observer (World::set_solve_observer, cps/step_system.h), for the tests that re-solve it.

#include "scene.h"

#include "cps/step_system.h"

#include <cstdint>
#include <optional>

namespace cps::test {

/// The first solve of step `step` (0 is the first) of the built-in scene `scene` under its own
/// parameters with `overrides`. Steps until that solve happens (the step must have one).
inline StepSystem capture(const char* scene, std::int64_t step, const scenes::Overrides& overrides) {
  scenes::Run run = scenes::make_run(*scenes::find_scene(scene), overrides);
  std::optional<StepSystem> captured;
  run.world.set_solve_observer([&](const StepSystem& s) {
    if (s.step == step && s.solve == 0) captured = s;
  });
  while (!captured) run.step();
  return *captured;
}

}  // namespace cps::test
