#pragma once
// Mass ratio stress scenes: a heavy cube resting on a light one on the ground. How PGS copes with
// a large mass ratio (paper Sec. 7.2 and 10): the scenes mass_ratio_10, _100, _1000 and the
// iteration count each ratio needs.

#include "scene.h"

namespace cps::scenes {

/// Light cube: edge 1 m, mass 1 kg; the heavy cube has the same edge and ratio x 1 kg.
inline constexpr double kMassRatioHalfEdge = 0.5;  // m
inline constexpr double kMassRatioLightMass = 1.0;  // kg

/// The world of the mass ratio scenes: the paper's settings (stack_world_def(): g = -10 m/s^2,
/// dt = 1/60 s, 25 iterations, beta = 0.2, mu = 0.5).
WorldDef mass_ratio_world_def();

/// Adds the static ground plane y = 0, the light cube (body 1) with its centre at (0, 0.5, 0)
/// and the heavy cube (body 2, ratio x 1 kg) at (0, 1.5, 0): both start exactly touching, at
/// rest. ratio: finite and > 0 (dimensionless); throws std::invalid_argument otherwise.
void populate_mass_ratio(World& world, double ratio);

/// What one mass ratio run ends with.
struct MassRatioOutcome {
  bool holds = false;               ///< see mass_ratio_holds
  double max_penetration_m = 0.0;   ///< deepest contact over the run (m)
  double final_penetration_m = 0.0; ///< deepest overlap at the end, from the geometry (m)
  double top_height_m = 0.0;        ///< heavy cube centre height at the end (m)
};

/// Adds the static ground plane y = 0 and a column of `boxes` cubes of edge 1 m (half edge
/// kMassRatioHalfEdge), resting on one another, touching, at rest: cube k (k = 0 at the bottom,
/// body k + 1) has its centre at (0, (2 k + 1) h, 0) and mass ratio^(k / (boxes - 1)) x 1 kg, so
/// that the top cube is `ratio` times the bottom one and each is the same factor heavier than
/// the one below. boxes = 2 is populate_mass_ratio. ratio: finite and > 0; boxes >= 2; throws
/// std::invalid_argument otherwise.
void populate_mass_ratio_stack(World& world, double ratio, int boxes);

/// True if the heavy cube's centre is above the light cube's centre and within 0.1 m of it
/// horizontally, and the deepest overlap now is below half the light cube's half edge (0.25 m).
/// world: a world made by populate_mass_ratio.
bool mass_ratio_holds(const World& world);

/// Runs the scene for `seconds` (s) with `iterations` PGS sweeps per solve (>= 1), everything
/// else as mass_ratio_world_def(). Throws std::invalid_argument for a bad ratio or iterations.
MassRatioOutcome run_mass_ratio(double ratio, int iterations, double seconds);

/// The smallest iteration count in {1, 2, 4, ..., 256} with which the pair holds and the deepest
/// overlap after 5 s is below 1 cm; -1 if none of them does. ratio as in populate_mass_ratio.
///
/// What to expect (a 1D model of the column, checked by tests/physics/test_stress.cpp): the ground row
/// and the cube-cube row form A = [[1/m1, -1/m1], [-1/m1, 1/m1 + 1/m2]]; Gauss-Seidel from 0
/// reduces the error of lambda by rho = A12^2 / (A11 A22) = R / (1 + R) per sweep, so after N
/// sweeps the ground row misses rho^N of the load and the pair sinks by rho^N g dt^2 per step,
/// which the push recovers at beta d per step: d = rho^N g dt^2 / beta. d < 1 cm needs
/// rho^N < 0.72, N > ln 0.72 / ln(R / (1 + R)): about 4 for R = 10, 33 for 100, 329 for 1000.
/// The 3D pair converges about four times slower (four corner rows per face, coupled through
/// the rotations) and fails sideways first (the light cube is walked out from under the heavy
/// one: the paper's friction limit mu m g uses the light cube's mass at the ground): measured
/// 2, 4, 16, 64, 128, -1, -1 for R = 1, 3, 10, 30, 100, 300, 1000. Runs at most 9 x 300 steps
/// (0.1 s for R = 1000).
int iterations_needed(double ratio);

}  // namespace cps::scenes
