#pragma once
// --compare and --overlay of `cps render` and `cps figure`: which world parameter is compared
// with which values (parsed and checked by the parameter table, cps/parameters.h, as the world
// options are), the variants and their labels, the grid the variants are laid out in, the name
// of the output, and the colours of the overlay's ghosts.

#include "scene.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace cps::cli {

/// Fewest and most variants a comparison may have (panels of a grid, ghosts of an overlay).
inline constexpr std::size_t kMinVariants = 2;
inline constexpr std::size_t kMaxVariants = 8;  // every push method side by side

/// One variant of a comparison: the overrides it runs with, the label of its panel (one or two
/// lines: "push factor constant beta (Eq. 5.2.3)\nbeta = 0.05"; empty for the single variant of
/// no comparison), and its one-line entry in an overlay's legend ("beta = 0.05",
/// "split: single frame push factor (Sec. 8.1)").
struct Variant {
  scenes::Overrides overrides;
  std::string label;
  std::string legend;
};

/// A --compare as given on the command line, parsed: the parameter and its values in the order
/// given. An empty spec gives no parameter and no values (no comparison).
struct Comparison {
  std::string spec;                         ///< as typed: "beta=0.05,0.2,0.5" or "push"
  const Parameter* parameter = nullptr;     ///< the compared parameter; null: no comparison
  std::vector<ParameterValue> values;       ///< kMinVariants..kMaxVariants distinct values
  bool every_choice = false;                ///< "--compare push": every value of a choice
};

/// The flags --compare takes: every parameter of the table that has a command-line flag and a
/// value without commas (real, integer, boolean or choice; a vector3 has none today).
std::vector<std::string> comparable_options();

/// comparable_options() as one text: "dt, iterations, beta, ...".
std::string comparable_list();

/// Parses --compare SPEC: "PARAM=V1,V2,..." (PARAM a flag of comparable_options(), each value
/// parsed and checked by the table's Parameter::parse) or "PARAM" alone for a choice parameter
/// (every value, in the table's order). `base` is the world options given besides. Throws
/// UsageError (exit 2), naming the spec and what is allowed, for: an unknown or not comparable
/// parameter, a value the table refuses (its message names the parameter, the value and the
/// allowed range), an empty value, fewer than kMinVariants or more than kMaxVariants values,
/// two values that are equal once parsed ("0.5" and "0.50"), "PARAM" alone for a parameter that
/// is not a choice, a parameter `base` also sets (its own option was given too), or solver,
/// friction model or warm start where `base` sets a push that does not read it (push_reads).
Comparison parse_comparison(const std::string& spec, const scenes::Overrides& base);

/// The variants of a comparison, one per value in order, each `base` with the value set and
/// labelled with the parameter's title from the table, its flag, the value and the unit (a
/// choice: the choice's title and source, "single frame push factor (Sec. 8.1)"). With no
/// comparison, the single variant `base` with empty labels.
std::vector<Variant> comparison_variants(const Comparison& comparison, const scenes::Overrides& base);

/// parse_comparison then comparison_variants.
std::vector<Variant> compare_variants(const std::string& spec, const scenes::Overrides& base);

/// The heading of an overlay's legend: the parameter's title for a number ("push factor
/// constant beta (Eq. 5.2.3)"), its flag for a choice ("push"); empty for no comparison.
std::string legend_heading(const Comparison& comparison);

/// The part of an output name that tells comparisons apart: "" for none; "-compare-PARAM" for
/// every value of a choice (as `--compare PARAM` always wrote); otherwise
/// "-compare-PARAM-V1_V2_..." with each value as the table formats it (shortest exact decimal,
/// or the choice's name), characters other than [A-Za-z0-9.+-] written as '-' so the name is
/// safe on any file system; then "-overlay" if `overlay`. Two different value lists (or orders)
/// of one parameter give different names, so neither run replaces the other's files.
std::string comparison_suffix(const Comparison& comparison, bool overlay);

/// What run.json and a figure's sidecar record of a comparison: null for none, else
/// {"spec", "parameter" (its flag), "json_key", "unit", "values" (as in run.json's parameters),
/// "layout": "grid" or "overlay"}.
nlohmann::json comparison_json(const Comparison& comparison, bool overlay);

/// Rows x columns of the grid of a render's variants, chosen so panels stay large: 1 -> 1x1,
/// 2 -> 1x2 when the frame is at least as wide as high (aspect = width / height >= 1), else
/// 2x1, 3 -> 1x3, 4 -> 2x2, 5 and 6 -> 2x3. Throws std::invalid_argument for 0 or more than
/// kMaxVariants variants.
struct Grid {
  int rows = 1;
  int columns = 1;
};
Grid grid_layout(std::size_t variants, double aspect);

/// The colour of variant k's ghosts in an overlay, as shown (sRGB, each in [0, 1]): blue,
/// orange, green, red, purple, olive, pink, teal (hues 25 degrees or more apart).
/// k < kMaxVariants, else std::out_of_range.
std::array<float, 3> overlay_colour(std::size_t k);

/// Opacity of the overlay's ghosts (dimensionless, in (0, 1)): where two variants coincide both
/// colours still show, and where they differ each ghost stays readable on the ground.
inline constexpr float kGhostAlpha = 0.55f;

}  // namespace cps::cli
