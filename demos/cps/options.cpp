#include "options.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <utility>
#include <vector>
#include <sstream>

namespace cps::cli {

namespace {

// The shortest decimal text that reads back as v (up to 17 significant digits).
std::string exact_text(double v) {
  char text[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}

}  // namespace

CLI::Validator decimal_in(double lo, double hi, bool lo_open, const std::string& unit,
                          bool allow_fraction) {
  const std::string range = std::string(lo_open ? "(" : "[") + exact_text(lo) + ", " +
                            exact_text(hi) + "]" + (unit.empty() ? "" : " " + unit);
  return CLI::Validator(
      [=](std::string& input) -> std::string {
        const std::optional<double> v = parse_decimal(input, allow_fraction);
        if (!v) {
          return input + ": not a number; give a decimal number" +
                 (allow_fraction ? std::string(" or a fraction such as 1/60") : "") + " in " + range;
        }
        if (!std::isfinite(*v) || (lo_open ? !(*v > lo) : !(*v >= lo)) || *v > hi) {
          return input + ": it must be in " + range;
        }
        input = exact_text(*v);
        return {};
      },
      range);
}

void add_seconds_option(CLI::App& cmd, std::optional<double>& seconds, const std::string& limits) {
  cmd.add_option("--seconds", seconds,
                 "simulated time (s) in (0, 1e5]; default: the scene's; " + limits)
      ->check(decimal_in(0.0, kMaxSeconds, true, "s"));
}

const CLI::Validator kNotEmpty(
    [](std::string& input) -> std::string {
      return input.empty() ? "an empty value is not allowed; give a name" : std::string();
    },
    "");

void check_steps(const std::string& what, double seconds, double dt) {
  const double steps = std::ceil(seconds / dt);
  if (steps > kMaxSteps) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "%s: %.6g s at dt = %.6g s is %.4g steps, more than the %.0f steps a run may "
                  "take; give fewer --seconds or a larger --dt",
                  what.c_str(), seconds, dt, steps, kMaxSteps);
    throw UsageError(text);
  }
}

std::string option_help(const Parameter& p) {
  std::string help(p.help);
  help += "; " + p.allowed() + "; default: the scene's";
  return help;
}

void add_world_options(CLI::App& cmd, scenes::Overrides& o) {
  for (const Parameter& p : world_parameters()) {
    if (p.flag.empty()) continue;
    const Parameter* param = &p;
    // The table parses and checks the text (its message names the flag, the value and what is
    // allowed); the callback runs only on text the check accepted.
    cmd.add_option_function<std::string>(
           "--" + std::string(p.flag),
           [param, &o](const std::string& text) { o.set(*param, param->parse(text)); },
           option_help(p))
        ->type_name(p.type == ParameterType::choice ? "{" + p.allowed().substr(8) + "}"
                    : p.type == ParameterType::integer ? "INT"
                                                       : "NUMBER")
        ->check(CLI::Validator(
            [param](std::string& text) -> std::string {
              try {
                param->parse(text);
              } catch (const std::invalid_argument& e) {
                // CLI11 puts the flag in front of the message already.
                const std::string why = e.what();
                const std::string prefix = "--" + std::string(param->flag) + " ";
                return why.rfind(prefix, 0) == 0 ? why.substr(prefix.size()) : why;
              }
              return {};
            },
            ""));
  }
}

std::vector<const scenes::Scene*> select_scenes(const std::string& name) {
  std::vector<const scenes::Scene*> selected;
  if (name == "all" || name == "stress") {
    for (const scenes::Scene& s : name == "all" ? scenes::paper_scenes() : scenes::stress_scenes()) {
      selected.push_back(&s);
    }
    return selected;
  }
  if (const scenes::Scene* s = scenes::find_scene(name)) return {s};
  std::string known;
  for (const scenes::Scene& s : scenes::all_scenes()) known += std::string(known.empty() ? "" : ", ") + std::string(s.name);
  std::string families;
  for (const std::string_view f : scenes::scaled_families()) {
    families += (families.empty() ? "" : ", ") + std::string(f);
  }
  throw UsageError("unknown scene '" + name + "'; the scenes are: " + known +
                   " (or 'all' for the paper's scenes, 'stress' for the stress scenes), and the "
                   "scaled scenes " + families + "; 'cps list' describes them");
}

scenes::Run make_run_or_usage_error(const scenes::Scene& scene, const scenes::Overrides& o) {
  try {
    return scenes::make_run(scene, o);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string(scene.name) + ": " + e.what());
  }
}

}  // namespace cps::cli
