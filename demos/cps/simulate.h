#pragma once
// `cps simulate`: runs a scene headless and reports its metrics.

#include "scene.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <string_view>

namespace cps::cli {

/// The first line of a trace CSV: the column names with their units. A file that starts with this
/// line was written by `cps simulate --trace` and may be replaced without --force.
inline constexpr std::string_view kTraceHeader =
    "step,t_s,body,x_m,y_m,z_m,qw,qx,qy,qz,vx_mps,vy_mps,vz_mps,wx_radps,wy_radps,wz_radps";

/// A per-step trace of every body (static ones too, their index as in World::bodies()): one row
/// per body per step, step 0 being the state as built; position x (m), orientation o (unit
/// quaternion w, x, y, z; body to world), linear velocity v (m/s), angular velocity w (rad/s).
/// Written to `path` + ".tmp" and renamed onto `path` by finish(), so an interrupted run never
/// leaves a half-written trace under the final name.
class TraceWriter {
 public:
  /// Refuses (UsageError) if `path` exists and does not start with kTraceHeader, unless `force`;
  /// opens the temporary file. Throws std::runtime_error naming the path if it cannot.
  TraceWriter(std::filesystem::path path, bool force);
  ~TraceWriter();
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  /// Appends one row per body of `world` for its current step.
  void write(const World& world);
  /// Closes the temporary file and renames it onto the path. Returns the number of rows
  /// written (header excluded). Throws std::runtime_error naming the path on failure.
  long finish();

 private:
  std::filesystem::path path_;
  std::filesystem::path tmp_;
  std::FILE* file_ = nullptr;
  long rows_ = 0;
};

/// Runs `run` until `seconds` (s) of simulated time and returns the report documented in
/// README.md: scene, engine_version, parameters, steps, simulated_s, wall_s, us_per_step,
/// metrics, counters, state_hash (scenes::state_hash of every body at the end, 16 hex digits) and
/// the final state of the movable bodies in creation order. With a `trace`, the state as built
/// and after every step is written to it (the wall time then includes the writing).
nlohmann::json simulate(const scenes::Scene& scene, scenes::Run& run, double seconds,
                        TraceWriter* trace = nullptr);

}  // namespace cps::cli
