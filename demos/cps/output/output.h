#pragma once
// The output rule of the cps command: every file cps writes (frames, videos, figures, traces,
// reports, run.json) goes through this module.
//  - Every target is checked before anything is written (plan_output). Each folder's run.json
//    records, for every file a cps run wrote there, the command that wrote it, the scene it shows
//    and its content's XXH3-64 hash. A file is cps's own only while it is listed there and its
//    content still has that hash; anything else (an unlisted file, a file edited since) is
//    foreign, and a run that would replace a foreign file is refused (UsageError, exit 2) naming
//    it. --force (the `force` field) lets a run replace a foreign file, or a file of another
//    scene, that has exactly the name of one of its targets; a file another command wrote is
//    never replaced, with or without it, and no other file is ever removed, truncated, renamed
//    or opened for writing. A target is never an input of the same command (note_input).
//  - Every file is written to a temporary of this run, created exclusively, checked and renamed
//    (atomic_file.h): a reader sees the old file or the new one, never a part, and a failed write
//    names the target and the OS's reason.
//  - Every folder written gets run.json (k_manifest_name): this run's parameters, the files cps
//    wrote there, and the runs still writing (their tokens), so that the leftover temporaries of
//    an interrupted run are removed by the next one, and nothing else is.

#include "output/atomic_file.h"
#include "scene.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace cps::cli {

/// The name of the manifest every output folder receives.
inline constexpr const char* k_manifest_name = "run.json";

/// How runs share an output folder.
enum class FolderUse {
  /// The folder holds one run's outputs and nothing else (render's OUT/SCENE/): any entry no
  /// earlier cps run listed is foreign and the folder is refused without force; a rerun removes
  /// the earlier runs' files it does not write again (a longer render's extra frames); run.json
  /// lists exactly this run's files. One run at a time: a folder another live cps run is writing
  /// is refused.
  exclusive,
  /// The folder collects the outputs of many runs, and may hold other files (figure's
  /// out/figures, render's OUT/ for videos, report's folders, a trace's folder): only this run's
  /// targets (and run.json) are checked; other entries, foreign or cps's, are left alone; runs
  /// may write it at the same time (run.json is updated under a lock). run.json lists every file
  /// a cps run wrote there that still exists, and describes the last run that began or ended.
  shared,
};

/// What one command asks to write into one folder.
struct OutputRequest {
  std::filesystem::path folder;    ///< may not exist yet; "" is the current folder
  std::vector<std::string> files;  ///< plain names (no '/', not "." or "..", not run.json)
  /// The command that writes them ("render", "figure", "simulate", "export", "scene",
  /// "report"): recorded per file; a file another command wrote is never replaced, nor removed
  /// as an exclusive folder's stale file.
  std::string command;
  FolderUse use = FolderUse::exclusive;
  /// The scene each file shows ("" or absent: none; see scene_source): a target that an earlier
  /// run wrote for another scene is refused without force, naming both.
  std::map<std::string, std::string> scenes;
  std::string option = "--out";  ///< the option that names the folder, for messages
  /// --force: foreign files (and other scenes' files) with a target's name are replaced.
  bool force = false;
};

/// What one run will write into one folder, decided (and checked) before anything is written.
struct OutputPlan {
  std::filesystem::path folder;          ///< may not exist yet; "" is the current folder
  FolderUse use = FolderUse::exclusive;  ///< how runs share it
  std::string command;                   ///< OutputRequest::command
  std::vector<std::string> files;  ///< names (in `folder`) this run writes, run.json aside
  std::map<std::string, std::string> scenes;  ///< OutputRequest::scenes
  std::vector<std::string> stale;  ///< exclusive: earlier runs' files (this command's) not rewritten
  std::vector<std::string> kept;   ///< exclusive: other commands' files, left and listed
};

/// Registers `path` as an input of this command (a scene file it reads): plan_output refuses a
/// target that is this file (the same inode, by any path), with or without force. Thread-safe.
void note_input(const std::filesystem::path& path);

/// Forgets the inputs noted so far, so that a process running several command lines
/// (run_command) checks each against its own. Thread-safe.
void clear_inputs();

/// Checks that `request.folder` may receive `request.files` and returns the plan. Reads only
/// (hashing the folder's own files); writes nothing. Throws UsageError (exit 2), naming the path
/// and what to do (`request.option` names the option to change):
///  - a file name that is not plain, or run.json;
///  - the folder exists and is not a folder, or it is missing and its nearest existing ancestor
///    is not a folder (`--out somefile/x`) or cannot be written into (no write or search
///    permission: checked with access(2), so not for root);
///  - a target is an input of this command (note_input), even with `force`;
///  - a target, or run.json, exists and is not a regular file or a symbolic link (a folder of
///    that name), even with `force`;
///  - a target exists and another command wrote it (run.json says so), even with `force`;
///  - without `force`: a target, or run.json, exists and is foreign: no earlier cps run wrote it
///    (it is not listed in the folder's run.json, or run.json is not cps's), or its content
///    changed since (its hash is not the one recorded); for an exclusive folder, also any other
///    entry that is foreign (a few are named, with their count);
///  - without `force`: a target exists that an earlier run wrote for another scene (both named);
///  - exclusive, without `force`: another cps run that may still be running (run.json lists it
///    as unfinished, and it ran on another host, or its process, same pid and start time, is
///    alive) is writing into the folder.
/// Leftover temporaries of an interrupted cps run (see begin_output) are the run's own, not
/// foreign. A missing folder is fine: begin_output creates it.
OutputPlan plan_output(const OutputRequest& request);

/// Starts writing a planned folder: creates it (and its parents), then, under an exclusive
/// flock(2) of the folder (best effort: skipped where the file system has none), removes the
/// leftover temporaries of interrupted runs and writes run.json with `info` (see run_info),
/// "tool": "cps", "complete": false, "files" (this run's targets, and the earlier runs' files
/// still present: an interrupted run remains recognised as cps's own by the next one),
/// "written" (the earlier files' records; this run's targets with their command and scene but
/// no hash until end_output, so that an interrupted run's files stay its own) and
/// "unfinished_runs" (each {"run_token", "pid", "host", "start", "files"}: this run's, and those
/// of other runs that may still be writing). A leftover is a file named temporary_name(F, T)
/// where T is the token of an unfinished run that is no longer running (same host, and its pid
/// is gone or started at another time) and F is run.json or one of that run's files; or a
/// temporary_name(run.json, T) whose content is a cps manifest listing T as such a run. Nothing
/// else is removed. Throws std::runtime_error naming the path if the folder, a removal or
/// run.json fails.
void begin_output(const OutputPlan& plan, const nlohmann::json& info);

/// After the run wrote its files (after begin_output): under the lock, removes `stale`
/// (exclusive), then rewrites run.json with `info`, this run taken off "unfinished_runs",
/// "complete": true if no run is left on it, "files": exclusive, this run's targets and the
/// other commands' files kept; shared, every file listed before or by this run that still
/// exists (or that a run still writing will write); and "written": for each listed file the
/// command, the scene and the XXH3-64 of its content as this run left it (this run's targets
/// are hashed now). Throws std::runtime_error naming the path on failure.
void end_output(const OutputPlan& plan, const nlohmann::json& info);

/// For a command that fails after begin_output: in each folder this process began and did not
/// end, takes this run off run.json's "unfinished_runs" and lists only the files that exist (or
/// that another run still writing will write), so run.json never names a file the failed run
/// did not write; a run.json that would then list nothing is removed. The failed run's
/// temporaries are removed by their AtomicFile. Best effort, no errors (a folder it cannot fix is
/// left as an interrupted run's, for the next run there).
void abandon_outputs() noexcept;

/// Writes `j` (indented, with a final newline) to `path` atomically (write_text_atomic). Throws
/// std::runtime_error "cannot write PATH: REASON" on failure; the old file, if any, stays.
void write_json_atomic(const std::filesystem::path& path, const nlohmann::json& j);

/// The description of this invocation for run.json: {"command": subcommand, "command_line":
/// [argv...], "engine_version": `git describe --always --dirty` at build time ("unknown" when built
/// outside git), "date_utc": ISO 8601 (YYYY-MM-DDTHH:MM:SSZ), "parameters": parameters}.
nlohmann::json run_info(const std::string& command, int argc, char** argv,
                        const nlohmann::json& parameters);

/// The scene a file shows, as run.json records it, from the scene's name as typed (Scene::name):
/// "scene NAME" for a built-in scene or example, "file PATH" for a scene file (a name ending in
/// ".json": its absolute path, symbolic links resolved, from the current folder). No errors.
std::string scene_source(std::string_view scene_name);

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
