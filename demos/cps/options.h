#pragma once
// Command-line options shared by the cps subcommands, and their validation.

#include "scene.h"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace cps::cli {

/// A usage error: a bad value on the command line. The command exits with code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The world parameter overrides every stepping command takes: one option per parameter of the
/// table (cps/parameters.h) that has a flag, its help, unit and allowed values from the table.
void add_world_options(CLI::App& cmd, scenes::Overrides& overrides);

/// CLI11 validator: a finite number > 0 (rejects nan and inf, which CLI::PositiveNumber lets by).
extern const CLI::Validator kFinitePositive;

/// Scenes named on the command line: "all" or one scene name. Throws UsageError listing the
/// scenes for an unknown name.
std::vector<const scenes::Scene*> select_scenes(const std::string& name);

/// One variant of a comparison: the overrides it runs with and its label ("push = split").
struct Variant {
  scenes::Overrides overrides;
  std::string label;
};

/// The flags of the parameters --compare takes: every choice parameter of the table.
std::vector<std::string> comparable_options();

/// The variants of `option` (a flag of comparable_options()), one per value in the table's
/// order, each on top of `base` and labelled "push = split (Sec. 8.1)"; with an empty option,
/// the single variant `base` with no label. Throws UsageError for another option, or if base
/// already sets the compared option.
std::vector<Variant> compare_variants(const std::string& option, const scenes::Overrides& base);

/// Builds a run and turns a bad parameter (std::invalid_argument) into a UsageError.
scenes::Run make_run_or_usage_error(const scenes::Scene& scene, const scenes::Overrides& o);

}  // namespace cps::cli
