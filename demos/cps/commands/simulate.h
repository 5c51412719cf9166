#pragma once
// `cps simulate`: runs a scene headless and reports its metrics.

#include "output/output.h"
#include "scene.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string_view>

namespace cps::cli {

/// The first line of a trace CSV: the column names with their units.
inline constexpr std::string_view kTraceHeader =
    "step,t_s,body,x_m,y_m,z_m,qw,qx,qy,qz,vx_mps,vy_mps,vz_mps,wx_radps,wy_radps,wz_radps";

/// A per-step trace of every body (static ones too, their index as in World::bodies()): one row
/// per body per step, step 0 being the state as built; position x (m), orientation o (unit
/// quaternion w, x, y, z; body to world), linear velocity v (m/s), angular velocity w (rad/s).
/// Written under the output rule (output.h): the trace's folder is a shared output folder whose
/// run.json lists it; the rows go to a temporary file of this run (AtomicFile) renamed onto the
/// path by finish(), so an interrupted run never leaves a half-written trace under the final name.
class TraceWriter {
 public:
  /// Checks the path (plan_output with option "--trace": UsageError if it exists and no earlier
  /// cps run wrote it, unless `force`; if it is a folder; if its folder cannot be created or
  /// written into), then creates the folder, records the run in its run.json (begin_output, with
  /// `info`, see run_info) and creates the temporary file. Throws std::runtime_error "cannot write
  /// PATH: REASON" if that fails.
  TraceWriter(std::filesystem::path path, bool force, nlohmann::json info);
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  /// Appends one row per body of `world` for its current step. Throws std::runtime_error
  /// "cannot write PATH: REASON" if a write fails (e.g. the disk is full); the temporary is then
  /// removed.
  void write(const World& world);
  /// Writes the rest, closes the temporary file and renames it onto the path, then lists it in
  /// the folder's run.json (end_output). Returns the number of rows written (header excluded).
  /// Throws std::runtime_error "cannot write PATH: REASON" on failure.
  long finish();

 private:
  std::filesystem::path path_;
  OutputPlan plan_;
  nlohmann::json info_;
  std::optional<AtomicFile> file_;
  long rows_ = 0;
};

/// Runs `run` until `seconds` (s) of simulated time and returns the report documented in
/// docs/commands.md, "simulate": scene, engine_version, parameters, steps, simulated_s, wall_s,
/// us_per_step, metrics, counters, state_hash (scenes::state_hash of every body at the end, 16
/// hex digits) and the final state of the movable bodies in creation order. With a `trace`, the
/// state as built and after every step is written to it (the wall time then includes the
/// writing).
nlohmann::json simulate(const scenes::Scene& scene, scenes::Run& run, double seconds,
                        TraceWriter* trace = nullptr);

}  // namespace cps::cli
