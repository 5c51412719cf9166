#include "options/options.h"

#include "output/output.h"
#include "scene_file.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <utility>
#include <vector>
#include <sstream>

namespace cps::cli {


CLI::Validator decimal_in(double lo, double hi, bool lo_open, const std::string& unit,
                          bool allow_fraction) {
  const std::string range = std::string(lo_open ? "(" : "[") + shortest_decimal(lo) + ", " +
                            shortest_decimal(hi) + "]" + (unit.empty() ? "" : " " + unit);
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
        input = shortest_decimal(*v);
        return {};
      },
      range);
}

void add_seconds_option(CLI::App& cmd, std::optional<double>& seconds, const std::string& limits) {
  cmd.add_option("--seconds", seconds,
                 "simulated time (s) in (0, 1e5], a decimal or a fraction such as 1/2; default: the "
                 "scene's; " + limits)
      ->transform(decimal_in(0.0, kMaxSeconds, true, "s", /*allow_fraction=*/true));
}

const CLI::Validator kNotEmpty(
    [](std::string& input) -> std::string {
      return input.empty() ? "an empty value is not allowed; give a name" : std::string();
    },
    "");

void check_steps(const std::string& what, double seconds, double dt) {
  if (seconds > 0.0 && std::llround(seconds / dt) < 1) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "%s: %.6g s at dt = %.6g s is less than one step; give --seconds of at least "
                  "dt (%.6g s) or a smaller --dt",
                  what.c_str(), seconds, dt, dt);
    throw UsageError(text);
  }
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

std::string count_text(double n) {
  char text[40];
  if (n < 1e7) {
    std::snprintf(text, sizeof text, "%.0f", n);
  } else {
    std::snprintf(text, sizeof text, "%.3g", n);
  }
  return text;
}

namespace {

// The push method's substeps a step (PushTraits::substeps): the work estimate's bound is
// substeps x iterations sweeps a step.
double substeps_of(const WorldDef& def) { return static_cast<double>(push_substeps(def)); }

}  // namespace

double run_work(std::size_t bodies, const WorldDef& def, double seconds) {
  const double steps = std::round(seconds / def.dt);
  return static_cast<double>(bodies) * steps * substeps_of(def) *
         static_cast<double>(def.iterations);
}

void add_max_work_option(CLI::App& cmd, double& max_work) {
  cmd.add_option("--max-work", max_work,
                 "work budget of a run in body-iterations (bodies x steps x substeps of the push "
                 "method x solver iterations), in [1, 1e18]; default " +
                     shortest_decimal(kDefaultMaxWork) +
                     "; a run past it is refused before any work (exit 2)")
      ->type_name("N")
      ->transform(decimal_in(1.0, kMaxMaxWork, false, "body-iterations"));
}

std::string lower_run_options(const WorldDef& def, const std::string& shorter) {
  const std::string_view substeps = push_traits(def.push).substeps;
  return "give " + shorter + ", a larger --dt, fewer --iterations" +
         (substeps.empty() ? std::string() : " or --" + std::string(parameter(substeps).flag)) +
         ", or raise --max-work";
}

void check_work(const std::string& what, std::size_t bodies, const WorldDef& def, double seconds,
                double max_work, const std::string& lower) {
  const double work = run_work(bodies, def, seconds);
  if (!(work > max_work)) return;
  const double substeps = substeps_of(def);
  throw UsageError(what + ": " + count_text(static_cast<double>(bodies)) + " bodies x " +
                   count_text(std::round(seconds / def.dt)) + " steps x " +
                   count_text(substeps) + (substeps == 1.0 ? " substep" : " substeps") + " x " +
                   count_text(def.iterations) + " iterations is " + count_text(work) +
                   " body-iterations of work, more than the budget of " + count_text(max_work) +
                   " body-iterations a run may take (--max-work); " + lower);
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
  try {
    if (const scenes::Scene* s = scenes::find_scene(name)) {
      if (name.ends_with(".json")) note_input(name);  // never an output of this command
      return {s};
    }
  } catch (const scenes::SceneFileError& e) {
    throw UsageError(e.what());
  }
  // A scaled family's name with a size it does not have: say the family's range.
  for (const std::string_view help : scenes::scaled_families()) {
    const std::string family(help.substr(0, help.find("_N")));
    if (name.rfind(family + "_", 0) == 0 && name.size() > family.size() + 1 &&
        std::isdigit(static_cast<unsigned char>(name[family.size() + 1]))) {
      throw UsageError("unknown scene '" + name + "': the scaled scenes " + std::string(help) +
                       " are named with N in that range, without leading zeros");
    }
  }
  std::vector<std::string> known = {"all", "stress"};
  for (const scenes::Scene& s : scenes::all_scenes()) known.emplace_back(s.name);
  for (const std::string_view e : scenes::example_scene_names()) known.emplace_back(e);
  for (const std::string_view help : scenes::scaled_families()) {
    known.emplace_back(help.substr(0, help.find(' ')));
  }
  // A scene file of that name beside it ("cradle" for ./cradle.json) is what was meant.
  std::error_code ec;
  if (std::filesystem::is_regular_file(name + ".json", ec)) {
    throw UsageError("unknown scene '" + name + "'; did you mean the scene file '" + name +
                     ".json' in this folder? (a scene file is given by its path, ending in .json)");
  }
  const std::string nearest = scenes::nearest_name(name, known);
  std::string suggestion = "'" + nearest + "'";
  // A scaled family ("pyramid_N"): its sizes, and a name that runs.
  for (const std::string_view help : scenes::scaled_families()) {
    if (help.substr(0, help.find(' ')) == nearest) {
      suggestion = std::string(help) + ", e.g. " + nearest.substr(0, nearest.size() - 1) + "10";
    }
  }
  throw UsageError("unknown scene '" + name + "'; did you mean " + suggestion +
                   "? ('cps list' shows the paper's and stress scenes, the example scene files, "
                   "random_SEED and the scaled families; or give the path of a scene file ending "
                   "in .json)");
}

std::string shell_quote(std::string_view text) {
  const auto safe = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           std::string_view("@%+=:,./_-").find(c) != std::string_view::npos;
  };
  if (!text.empty() && std::all_of(text.begin(), text.end(), safe)) return std::string(text);
  std::string quoted = "'";
  for (const char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

std::string with_seed(const std::string& scene, std::uint64_t seed) {
  const std::string seeded = "random_" + std::to_string(seed);
  if (scene == "random" || scene == seeded) return seeded;
  if (scene.rfind("random_", 0) == 0) {
    throw UsageError("--seed " + std::to_string(seed) + ": the scene " + scene +
                     " already names its seed; give the seed once (random --seed N, or random_N)");
  }
  throw UsageError("--seed " + std::to_string(seed) + ": the scene " + scene +
                   " is not random; --seed applies to the random scene only (random, random_N)");
}

namespace {

// Adds --seed to `cmd`; `apply` turns the seed into scene names once the command line is parsed.
void add_seed(CLI::App& cmd, std::function<void(std::uint64_t)> apply) {
  auto seed = std::make_shared<std::optional<std::uint64_t>>();
  cmd.add_option_function<std::string>(
         "--seed",
         [seed](const std::string& text) { *seed = std::stoull(text); },
         "seed of the random scene (an integer in [0, 18446744073709551615]): 'random --seed 7' "
         "is random_7; refused for any other scene")
      ->type_name("INT")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            std::uint64_t v = 0;
            const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
            if (text.empty() || ec != std::errc() || end != text.data() + text.size()) {
              return text + ": not allowed; give a decimal integer in [0, 18446744073709551615]";
            }
            return {};
          },
          ""));
  cmd.parse_complete_callback([seed, apply = std::move(apply)] {
    if (!seed->has_value()) return;
    try {
      apply(**seed);
    } catch (const UsageError& e) {
      // A CLI11 parse error: main reports it and exits 2.
      throw CLI::ValidationError(e.what());
    }
  });
}

}  // namespace

std::vector<long long> parse_counts(const std::string& text, long long lo, long long hi,
                                    const std::string& option, const std::string& what) {
  std::vector<long long> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    long long value = 0;
    const auto [ptr, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() || value < lo ||
        value > hi) {
      throw UsageError(option + " " + text + ": '" + item + "' is not " + what +
                       ": give comma-separated integers in [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "]");
    }
    out.push_back(value);
    if (end == text.size()) break;
    start = end + 1;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void add_seed_option(CLI::App& cmd, std::string& scene) {
  add_seed(cmd, [&scene](std::uint64_t seed) { scene = with_seed(scene, seed); });
}

void add_seed_option(CLI::App& cmd, std::vector<std::string>& scenes) {
  add_seed(cmd, [&scenes](std::uint64_t seed) {
    if (scenes.empty()) {
      throw UsageError("--seed " + std::to_string(seed) + ": no scene is random; --seed applies "
                       "to the random scene (--scene random)");
    }
    for (std::string& s : scenes) s = with_seed(s, seed);
  });
}

scenes::Run make_run_or_usage_error(const scenes::Scene& scene, const scenes::Overrides& o) {
  try {
    return scenes::make_run(scene, o);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string(scene.name) + ": " + e.what());
  }
}

}  // namespace cps::cli
