#pragma once
// `cps simulate`: runs a scene headless and reports its metrics.

#include "scene.h"

#include <nlohmann/json.hpp>

namespace cps::cli {

/// Runs `run` until `seconds` (s) of simulated time and returns the report documented in
/// README.md: scene, parameters, steps, simulated_s, wall_s, us_per_step, metrics, counters and
/// the final state of the movable bodies in creation order.
nlohmann::json simulate(const scenes::Scene& scene, scenes::Run& run, double seconds);

/// Every world parameter with its value, keys suffixed with their unit.
nlohmann::json parameters_json(const WorldDef& def);

}  // namespace cps::cli
