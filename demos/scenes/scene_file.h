#pragma once
// Scene files: a scene written as JSON (assets/schemas/scene.schema.json is the format's source
// of truth; docs/scene-files.md describes it). A file is checked in three passes, each
// error naming the file, the JSON pointer of the bad value (/bodies/3/mass_kg), the value and
// what is allowed:
//   1. syntax (nlohmann-json, comments allowed): the line and column; also refused there, with
//      the pointer: nesting deeper than kMaxSceneFileDepth, a key twice in one object, a number
//      out of the range of a double, and a NUL byte or anything else after the document;
//   2. the schema (valijson): types, ranges, required and unknown keys (an unknown key names the
//      nearest known one, so that a typo never falls back to a default silently);
//   3. the engine's own checks: the parameter table for world parameters, make_body for bodies,
//      World::add_distance for rods, and the format's rules the schema cannot say (rod body
//      references, unique body names, a movable body's mass, a unit quaternion).
// A loaded file becomes a Scene kept in a registry for the program's life (Scene's string_views
// point into it), so find_scene() hands out file scenes like built-in ones.

#include "scene.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace cps::scenes {

/// A scene file that cannot be read or is not valid. what() is one line: "FILE: /pointer: the
/// value and what is allowed" (or "FILE:LINE:COLUMN: ..." for a syntax error).
struct SceneFileError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// One body of a scene file: what World::add_body takes, plus its name ("" if none) and its
/// colour (linear RGB, each in [0, 1]; unset: the renderer's palette).
struct FileBody {
  BodyDef def;
  std::string name;
  std::optional<Vec3> colour;
};

/// The content of a scene file, checked (every body and rod was accepted by a World).
struct SceneFile {
  std::string origin;       ///< the file as named in messages (a path, or "example dominoes")
  std::string name;         ///< "name", or "" (the scene is still called by its path)
  std::string description;  ///< "description", or ""
  double seconds = 10.0;    ///< "seconds": the default simulated time (s), in (0, 1e5]
  double plane_opacity = 1.0;  ///< "plane_opacity" in [0, 1]
  WorldDef world;              ///< "world": the table's defaults where a key is omitted
  std::vector<FileBody> bodies;
  std::vector<DistanceConstraint> rods;  ///< bodies by index; body_b kWorldBody for null
  std::optional<CameraPreset> camera;
};

/// Parses and checks the text of a scene file; `origin` names it in messages. Throws
/// SceneFileError (see the file comment for what is checked).
SceneFile parse_scene_file(std::string_view text, const std::string& origin);

/// Reads and parses the file at `path`. Throws SceneFileError naming the path if it does not
/// exist, is not a regular file, cannot be read or is larger than kMaxSceneFileBytes, or for any
/// error parse_scene_file finds.
SceneFile read_scene_file(const std::filesystem::path& path);

/// The largest scene file read (bytes): 64 MiB, about 300,000 bodies written out in full.
inline constexpr std::uintmax_t kMaxSceneFileBytes = 64u << 20;

/// The deepest nesting of objects and arrays a scene file may have (count): a scene file needs 4
/// (the file, "bodies", a body, its "position_m"); deeper text is refused before it is built, so
/// that no message or check recurses through it.
inline constexpr std::size_t kMaxSceneFileDepth = 32;

/// The scene a SceneFile describes, named `name`: populate adds its bodies and rods, its metrics
/// are FileSceneMetrics, summary its name and description. The Scene's views point into `file`
/// and `name`, which must outlive it (load_scene_file keeps them for the program's life).
Scene scene_of(const SceneFile& file, std::string_view name);

/// The name of a scene file's outputs (output_name in scene.h): its "name" when that is 1 to 64
/// bytes of letters, digits, '_', '-', '.' or non-ASCII UTF-8 that does not begin with '.' or
/// '-' ("cradle"); else the stem of `path` (the file name without ".json", spaces and unicode
/// kept) when that is a usable file name (not empty, no control character, not beginning with
/// '.', at most 200 bytes); else "scene". Never the path as typed. Throws SceneFileError when the
/// name chosen is one of cps's own outputs (kReservedOutputNames), or when the "name" or the stem
/// holds a character no file name of cps may hold (unsafe_name_character).
std::string scene_file_output_name(const SceneFile& file, const std::filesystem::path& path);

/// Output names a scene may not have: cps's own files beside its outputs ("run" would make
/// `scene`'s run.json, "run.json" render's frames folder OUT/run.json beside OUT's own run.json,
/// "report" and "mass_ratio" the report's report.md and mass_ratio.csv, "plots" the report's
/// plots folder).
inline constexpr std::string_view kReservedOutputNames[] = {"run", "run.json", "report", "mass_ratio",
                                                            "plots"};

/// The first character of UTF-8 text `s` that a name of cps's outputs may not hold, as "U+XXXX"
/// with what it is ("a control character", "a bidirectional control", "a line or paragraph
/// separator"), or "invalid UTF-8 at byte N"; "" when there is none. Such characters make a name
/// print as another (U+202E turns the text after it around) or break a line. No errors.
std::string unsafe_name_character(std::string_view s);

/// The scene file at `path` (a name ending in ".json"), loaded once and kept for the program's
/// life; the Scene is named `path` as given. Throws SceneFileError for a file that cannot be read
/// or is not valid. Thread safe.
const Scene* load_scene_file(std::string_view path);

/// The example scene files (assets/scenes/*.json, embedded into the binary at build time), by
/// name: the file name without ".json" ("dominoes"); their Scenes are built on first use.
std::span<const std::string_view> example_scene_names();

/// The example called `name`, or nullptr. Its origin in messages is "assets/scenes/NAME.json".
const Scene* find_example_scene(std::string_view name);

/// The text of an example scene file, or "" for an unknown name.
std::string_view example_scene_text(std::string_view name);

/// The colours of a scene's bodies by body index (linear RGB, each in [0, 1]; unset: the
/// renderer's palette): a scene file's "color"s; empty for a scene that is not a loaded file.
std::span<const std::optional<Vec3>> body_colours(const Scene& scene);

/// True for a scene loaded from a file (load_scene_file) or an example file (find_example_scene);
/// false for a built-in scene. No errors.
bool is_file_scene(const Scene& scene);

/// The names of a scene's bodies by body index (a scene file's "name"s, "" where a body has
/// none); empty for a scene that is not a loaded file.
std::vector<std::string> body_names(const Scene& scene);

/// The JSON Schema of the format (assets/schemas/scene.schema.json, embedded at build time).
std::string_view scene_schema_text();

/// The scene file of a world as built: every world parameter by its JSON key, every body and rod
/// as the world holds them, with the scene's name, description, duration, camera and plane
/// opacity. Running the file steps exactly as the scene does (the same state_hash) when its
/// bodies' initial state can be written so that make_body rebuilds the same bits; see
/// docs/scene-files.md, "Writing a scene as a file", for the scenes where it cannot.
nlohmann::json scene_file_json(const Scene& scene, const World& as_built);

/// Measurements that apply to any world, for scene files (keys carry units as suffixes):
/// initial and final kinetic_energy_J and potential_energy_J (-m g . x of the movable bodies,
/// datum x = 0), energy_drift_J (final minus initial total) and relative_energy_drift (that over
/// the initial total's magnitude; null when it is 0), max_penetration_m (the deepest contact of
/// any step), final_penetration_m (of the last step), max_rod_error_m (largest |distance -
/// length| of any rod at any step), max_speed_mps and fastest_body (its index) over the run, and
/// nan (true once a state was not finite).
class FileSceneMetrics final : public Metrics {
 public:
  explicit FileSceneMetrics(const World& world);
  void observe(const World& world) override;
  nlohmann::json report() const override;

 private:
  double initial_kinetic_ = 0.0;
  double initial_potential_ = 0.0;
  double kinetic_ = 0.0;
  double potential_ = 0.0;
  double max_penetration_ = 0.0;
  double final_penetration_ = 0.0;
  double max_rod_error_ = 0.0;
  double max_speed_ = 0.0;
  int fastest_body_ = -1;
  bool nan_ = false;
};

/// Potential energy -m g . x (J) of the movable bodies (datum x = 0).
double potential_energy(const World& world);

}  // namespace cps::scenes
