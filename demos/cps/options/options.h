#pragma once
// Command-line options shared by the cps subcommands, and their validation.

#include "options/cli_fwd.h"
#include "options/compare.h"
#include "scene.h"
#include "usage_error.h"

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cps::cli {

/// The world parameter overrides every stepping command takes: one option per parameter of the
/// table (cps/parameters.h) that has a flag, its help, unit and allowed values from the table.
void add_world_options(CLI::App& cmd, scenes::Overrides& overrides);

/// Limits that keep one command's work finite. Each is stated in the --help of the options it
/// bounds, and a command that would pass one is refused before any work (exit 2), naming the
/// limit and the value.
inline constexpr double kMaxSeconds = 1.0e5;  ///< s of simulated time a run (--seconds, --times)
inline constexpr double kMaxSteps = 1.0e7;    ///< physics steps a run: seconds / dt
inline constexpr double kMaxFps = 1000.0;     ///< frames per simulated second (--fps)
inline constexpr double kMaxFrames = 1.0e5;   ///< frames in one render folder
/// Raw pixel bytes one render may draw (frames x width x height x 3): 64 GiB. The PNG files
/// are smaller; this bounds the drawing work.
inline constexpr double kMaxPixelBytes = 68719476736.0;

/// A count (n >= 0) as text for messages: whole below 1e7 ("6000000"), else 3 significant digits
/// ("3.6e+14"). No errors.
std::string count_text(double n);

/// Default work budget of one run (body-iterations, see run_work), the default of --max-work.
/// Typical runs: 9e4 (the stack), 1.5e9 (pendulum_wave_20000); docs/commands.md says why 1e11.
inline constexpr double kDefaultMaxWork = 1.0e11;
/// Largest --max-work (body-iterations).
inline constexpr double kMaxMaxWork = 1.0e18;

/// CLI11 validator for a decimal number (parse_decimal: no hex, no trailing text; a fraction such
/// as 1/60 when allow_fraction) in [lo, hi], or (lo, hi] when lo_open, in `unit`. It hands CLI11
/// the number written back in decimal, so CLI11 converts exactly the value checked. Its message
/// names the text and the range.
CLI::Validator decimal_in(double lo, double hi, bool lo_open, const std::string& unit,
                          bool allow_fraction = false);

/// Adds --seconds (simulated time, s, in (0, kMaxSeconds]; unset: the scene's default) to a
/// command; `limits` says which further limits the command applies (appended to the help).
void add_seconds_option(CLI::App& cmd, std::optional<double>& seconds, const std::string& limits);

/// CLI11 validator that refuses an empty value ("--out ''").
extern const CLI::Validator kNotEmpty;

/// The work of a run, in body-iterations: bodies x steps x substeps x iterations, where steps is
/// round(seconds / def.dt), substeps is def.soft_substeps for the soft step (push soft),
/// def.tgs_substeps for push tgs, def.xpbd_substeps for push xpbd (upper bounds of their sweeps
/// over iterations) and 1 otherwise, and iterations is def.iterations. bodies: the world's bodies after populate
/// (static ones too). seconds >= 0 (s). A measure of the solver's cost, not a time. No errors.
double run_work(std::size_t bodies, const WorldDef& def, double seconds);

/// Adds --max-work N (body-iterations in [1, kMaxMaxWork], default kDefaultMaxWork) to a
/// stepping command: the work budget of each of its runs.
void add_max_work_option(CLI::App& cmd, double& max_work);

/// Throws UsageError when run_work(bodies, def, seconds) exceeds max_work (body-iterations),
/// naming the run (`what`), the factors and the estimate, the budget and --max-work, and
/// `lower`: what to change instead ("give fewer --seconds ..."). No work is done.
void check_work(const std::string& what, std::size_t bodies, const WorldDef& def, double seconds,
                double max_work, const std::string& lower);

/// The comma-separated integers of `text`, each in [lo, hi], sorted and without repeats. Throws
/// UsageError naming `option`, the text, the bad item and the range for an empty item, a sign,
/// a fraction, trailing text or a value out of range; `what` names an item ("a step of this run").
std::vector<long long> parse_counts(const std::string& text, long long lo, long long hi,
                                    const std::string& option, const std::string& what);

/// `lower` for check_work in a command that takes the world options: `shorter` (how to shorten
/// the run), --dt, --iterations, and --soft-substeps, --tgs-substeps or --xpbd-substeps when
/// def's push is soft, tgs or xpbd.
std::string lower_run_options(const WorldDef& def, const std::string& shorter = "fewer --seconds");

/// Throws UsageError naming the run, the steps it would take and kMaxSteps when seconds / dt
/// (s / s) exceeds kMaxSteps, and naming dt when seconds > 0 rounds to no step at all (a run
/// takes round(seconds / dt) steps). seconds = 0 (a figure at the start only) takes none.
void check_steps(const std::string& what, double seconds, double dt);

/// Scenes named on the command line: "all", "stress", one scene name (see scenes::find_scene:
/// the tables, the example scene files, random_SEED, the scaled families) or the path of a scene
/// file (ending in ".json"). Throws UsageError listing the scenes, the example files and the
/// scaled families for an unknown name, and with the file's own message (file, JSON pointer,
/// value, what is allowed) for a scene file that cannot be read or is not valid.
std::vector<const scenes::Scene*> select_scenes(const std::string& name);

/// Adds --seed N (the random scene's seed, a decimal integer in [0, 2^64 - 1]) to a command that
/// takes the scene `scene` (or the scenes `scenes`): once the command line is parsed, it turns
/// "random" (or random_N with the same N) into random_N. A scene that is not random is refused
/// (exit 2, naming the scene), as is a random_M with another seed.
void add_seed_option(CLI::App& cmd, std::string& scene);
void add_seed_option(CLI::App& cmd, std::vector<std::string>& scenes);

/// The scene name `scene` with the seed applied (see add_seed_option). Throws UsageError for a
/// scene that is not random, or random_M with M != seed.
std::string with_seed(const std::string& scene, std::uint64_t seed);

// Variant, comparable_options and compare_variants (--compare): compare.h.

/// `text` as one word of a POSIX shell command (sh, dash, bash), for every command line cps
/// prints for a shell: as it is when non-empty and made only of letters, digits and @%+=:,./_-
/// (which no shell reads specially there); otherwise in single quotes, each ' inside written as
/// '\'' (close, an escaped quote, open again), every other byte, newlines included, standing for
/// itself. Source: POSIX.1-2017, Shell Command Language, 2.2.3 Single-Quotes (the unquoted set as
/// Python's shlex.quote). Throws nothing.
std::string shell_quote(std::string_view text);

/// Builds a run and turns a bad parameter (std::invalid_argument) into a UsageError.
scenes::Run make_run_or_usage_error(const scenes::Scene& scene, const scenes::Overrides& o);

}  // namespace cps::cli
