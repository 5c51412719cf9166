#pragma once
// Output folders that are safe to rerun: a run writes only the files it announces, never
// deletes or overwrites files it did not create, and leaves run.json (its manifest and its
// exact parameters) in every folder it writes.

#include "scene.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace cps::cli {

/// The name of the manifest every output folder receives.
inline constexpr const char* k_manifest_name = "run.json";

/// What one run will write into one folder, decided (and checked) before anything is written.
struct OutputPlan {
  std::filesystem::path folder;
  std::vector<std::string> files;      ///< names (in `folder`) this run writes
  std::vector<std::string> stale;      ///< the previous run's own files this run does not rewrite
  std::vector<std::string> leftovers;  ///< temporary files ("NAME.tmp") of an interrupted own run
};

/// Checks that `folder` may receive `files` (plain names, no '/'). The folder may be missing,
/// empty, or hold only what an earlier cps run listed in its run.json (with their ".tmp"
/// temporaries); those files are the run's own and may be replaced, and the ones the new run
/// does not write are removed by end_output. Any other entry (a file or folder cps did not list,
/// or a run.json that is not cps's) is foreign: without `force` this throws UsageError naming the
/// folder, a few of the foreign entries, and what to do (--force, which keeps them, or another
/// --out). Foreign entries are never removed, even with force (a foreign file with the name of
/// one of `files` is overwritten with force). Also a UsageError: `folder` exists and is not a
/// directory. Reads only; writes nothing.
OutputPlan plan_output(const std::filesystem::path& folder, std::vector<std::string> files,
                       bool force);

/// Creates the folder and writes run.json with `info` (see run_info), "complete": false, and the
/// files of this run together with the previous run's own files still present, so that an
/// interrupted run remains recognised as cps's own by the next one. Throws std::runtime_error
/// (naming the path) if the folder or run.json cannot be written.
void begin_output(const OutputPlan& plan, const nlohmann::json& info);

/// After the run wrote its files: removes `stale` and `leftovers`, then rewrites run.json with
/// "complete": true and exactly plan.files. Throws std::runtime_error naming the path on failure.
void end_output(const OutputPlan& plan, const nlohmann::json& info);

/// Writes `j` (indented) to `path` through "<path>.tmp" and a rename, so readers see the old or
/// the new file, never a partial one. Throws std::runtime_error naming the path on failure.
void write_json_atomic(const std::filesystem::path& path, const nlohmann::json& j);

/// The description of this invocation for run.json: {"command": subcommand, "command_line":
/// [argv...], "engine_version": `git describe --always --dirty` at build time ("unknown" when built
/// outside git), "date_utc": ISO 8601 (YYYY-MM-DDTHH:MM:SSZ), "parameters": parameters}.
nlohmann::json run_info(const std::string& command, int argc, char** argv,
                        const nlohmann::json& parameters);

/// One parameter's value as JSON: a number, a bool, [x, y, z], or a choice's name.
nlohmann::json parameter_json(const Parameter& p, const ParameterValue& v);

/// The overrides given on the command line, by the table's JSON key ("dt_s", "iterations",
/// "push", ...; units as the key's suffix); an empty object when none.
nlohmann::json overrides_json(const scenes::Overrides& overrides);

/// Every world parameter with its value, by the table's JSON key.
nlohmann::json parameters_json(const WorldDef& def);

/// `git describe --always --dirty` of the sources at build time, or "unknown".
const char* engine_version();

}  // namespace cps::cli
