#pragma once
// `cps simulate`: runs a scene headless and reports its metrics.

#include "output/output.h"
#include "scene.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cps::cli {

/// The first line of a trace CSV: the column names with their units.
inline constexpr std::string_view kTraceHeader =
    "step,t_s,body,x_m,y_m,z_m,qw,qx,qy,qz,vx_mps,vy_mps,vz_mps,wx_radps,wy_radps,wz_radps";

/// The first line of an energy CSV (--energy): the column names with their units.
inline constexpr std::string_view kEnergyHeader =
    "step,t_s,kinetic_J,potential_J,total_J,penetration_m,rod_error_m";

/// The most rows an energy CSV may have (header excluded): 1e6 rows of about 100 bytes, some
/// 100 MB. A run that would write more is refused before any step, naming --energy-every.
inline constexpr long long kMaxEnergyRows = 1'000'000;
/// Rows a --trace file may have (one per body per step, step 0 included): 1e7 rows of about
/// 105 bytes, some 1 GB. A run that would write more is refused before any step.
inline constexpr long long kMaxTraceRows = 10'000'000;

/// The rows an energy CSV of a run of `steps` steps gets with one row every `every` steps
/// (>= 1): steps 0, every, 2 every, ..., and the last step if it is not one of them.
long long energy_rows(long long steps, long long every);

/// A file `cps simulate` writes: its path and the option that names it ("--trace", "--energy").
struct SimulateTarget {
  std::filesystem::path path;
  std::string option;
};

/// The files of one `cps simulate` run (--trace, --energy), written under the output rule
/// (output.h): every target is checked before any is written, its folder is a shared output
/// folder whose run.json lists it, and its rows go to a temporary file of this run (AtomicFile)
/// renamed onto the path by finish(), so an interrupted run never leaves a half-written file
/// under the final name. Targets in one folder share one plan (and one entry of this run in its
/// run.json).
class SimulateFiles {
 public:
  /// Checks every target (plan_output with its option: UsageError if it exists and no earlier
  /// cps run wrote it, unless `force`; if it is a folder; if its folder cannot be created or
  /// written into; if an earlier run wrote it for another scene than `scene`, a scene_source,
  /// unless `force`) and that no two targets are one file (UsageError naming both options).
  /// Writes nothing.
  SimulateFiles(std::vector<SimulateTarget> targets, const std::string& scene, bool force);
  SimulateFiles(const SimulateFiles&) = delete;
  SimulateFiles& operator=(const SimulateFiles&) = delete;

  /// Creates the folders, records the run in their run.json (begin_output with `info`, see
  /// run_info) and creates the temporary files. Throws std::runtime_error "cannot write PATH:
  /// REASON" if that fails.
  void begin(const nlohmann::json& info);
  /// The temporary file of target i (in the order given), after begin().
  AtomicFile& file(std::size_t i) { return *files_.at(i); }
  /// Closes each temporary file and renames it onto its path, then lists the files in their
  /// folders' run.json (end_output). Throws std::runtime_error "cannot write PATH: REASON".
  void finish();

 private:
  std::vector<SimulateTarget> targets_;
  std::vector<OutputPlan> plans_;
  nlohmann::json info_;
  std::vector<std::unique_ptr<AtomicFile>> files_;  // by target
};

/// A per-step trace of every body (static ones too, their index as in World::bodies()): one row
/// per body per step, step 0 being the state as built; position x (m), orientation o (unit
/// quaternion w, x, y, z; body to world), linear velocity v (m/s), angular velocity w (rad/s).
/// Written to a file of SimulateFiles.
class TraceWriter {
 public:
  /// Writes the header (kTraceHeader) to `file`, which must outlive this.
  explicit TraceWriter(AtomicFile& file);

  /// Appends one row per body of `world` for its current step. Throws std::runtime_error
  /// "cannot write PATH: REASON" if a write fails (e.g. the disk is full); the temporary is then
  /// removed.
  void write(const World& world);
  /// The rows written so far (header excluded).
  long rows() const { return rows_; }

 private:
  AtomicFile* file_;
  long rows_ = 0;
};

/// The energy over time of a run (--energy): one row per `every` steps, step 0 being the state as
/// built and the last step always written. Columns (kEnergyHeader): the step; the time t (s);
/// the kinetic energy (J, translational plus rotational), the potential energy of gravity (J,
/// datum x = 0) and their sum, of the movable bodies (scenes::mechanical_energy); the deepest
/// penetration of the step's contacts (m: scenes::deepest_contact, the overlaps its collision
/// stage found at its start, i.e. in the state of the step before, which the step corrected; 0 in
/// row 0, before any step); the largest rod error |distance - length| over the distance
/// constraints in the row's state (m: scenes::max_rod_error; 0 without rods). Written to a file
/// of SimulateFiles.
class EnergyWriter {
 public:
  /// Writes the header to `file`, which must outlive this. every >= 1 (steps).
  EnergyWriter(AtomicFile& file, long long every);

  /// Appends the row of `world`'s current step if it is a multiple of `every`.
  /// Throws std::runtime_error "cannot write PATH: REASON" if a write fails.
  void write(const World& world);
  /// Appends the row of the last step if write() skipped it. Throws as write().
  void write_last(const World& world);
  /// The rows written so far (header excluded).
  long long rows() const { return rows_; }

 private:
  void row(const World& world);

  AtomicFile* file_;
  long long every_;
  long long last_step_ = -1;
  long long rows_ = 0;
};

/// Runs `run` until `seconds` (s) of simulated time and returns the report documented in
/// docs/commands.md, "simulate": scene, engine_version, parameters, steps, simulated_s, wall_s,
/// us_per_step, metrics, counters, state_hash (scenes::state_hash of every body at the end, 16
/// hex digits) and the final state of the movable bodies in creation order. With a `trace` or an
/// `energy` writer, the state as built and after every step is written to it (the wall time then
/// includes the writing).
nlohmann::json simulate(const scenes::Scene& scene, scenes::Run& run, double seconds,
                        TraceWriter* trace = nullptr, EnergyWriter* energy = nullptr);

}  // namespace cps::cli
