#include "options.h"

#include <cmath>
#include <utility>
#include <vector>
#include <sstream>

namespace cps::cli {

const CLI::Validator kFinitePositive(
    [](std::string& input) -> std::string {
      double value = 0.0;
      std::istringstream s(input);
      if (!(s >> value) || !std::isfinite(value) || value <= 0.0) {
        return "value " + input + " must be a finite number > 0";
      }
      return {};
    },
    "POSITIVE");

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
  throw UsageError("unknown scene '" + name + "'; the scenes are: " + known +
                   " (or 'all' for the paper's scenes, 'stress' for the stress scenes); 'cps list' "
                   "describes them");
}

std::vector<std::string> comparable_options() {
  std::vector<std::string> names;
  for (const Parameter& p : world_parameters()) {
    if (p.type == ParameterType::choice && !p.flag.empty()) names.emplace_back(p.flag);
  }
  return names;
}

std::vector<Variant> compare_variants(const std::string& option, const scenes::Overrides& base) {
  if (option.empty()) return {{base, ""}};
  const Parameter* p = find_parameter(option);
  if (p == nullptr || p->type != ParameterType::choice || p->flag != option) {
    std::string allowed;
    for (const std::string& n : comparable_options()) allowed += (allowed.empty() ? "" : ", ") + n;
    throw UsageError("--compare " + option + ": allowed are " + allowed);
  }
  if (base.find(p->name) != nullptr) {
    throw UsageError("--compare " + option + " renders every value of --" + option +
                     "; do not set --" + option + " as well");
  }
  std::vector<Variant> v;
  for (const Choice& c : p->choices) {
    Variant variant{base, std::string(p->name) + " = " + std::string(c.name)};
    for (char& ch : variant.label) {
      if (ch == '_') ch = ' ';
    }
    if (!c.source.empty()) variant.label += " (" + std::string(c.source) + ")";
    variant.overrides.set(*p, c.value);
    v.push_back(std::move(variant));
  }
  return v;
}

scenes::Run make_run_or_usage_error(const scenes::Scene& scene, const scenes::Overrides& o) {
  try {
    return scenes::make_run(scene, o);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string(scene.name) + ": " + e.what());
  }
}

}  // namespace cps::cli
