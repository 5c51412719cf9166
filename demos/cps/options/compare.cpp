#include "options/compare.h"

#include "options/options.h"
#include "output/output.h"

#include <cstdio>
#include <stdexcept>
#include <utility>

namespace cps::cli {
namespace {

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

bool comparable(const Parameter& p) {
  return !p.flag.empty() && p.type != ParameterType::vector3;
}

// Equal once parsed: the same number (0.5 and 0.50), the same choice.
bool same_value(const Parameter& p, const ParameterValue& a, const ParameterValue& b) {
  if (std::holds_alternative<double>(a) && std::holds_alternative<double>(b)) {
    return std::get<double>(a) == std::get<double>(b);
  }
  return p.format(a) == p.format(b);
}

// A value for a label: 6 significant digits for reals (1/60 reads 0.0166667), else exact.
std::string short_text(const Parameter& p, const ParameterValue& v, bool exact) {
  if (exact || p.type != ParameterType::real || !std::holds_alternative<double>(v)) {
    return p.format(v);
  }
  char text[40];
  std::snprintf(text, sizeof text, "%.6g", std::get<double>(v));
  return text;
}

std::string unit_text(const Parameter& p) { return p.unit.empty() ? "" : " " + std::string(p.unit); }

}  // namespace

std::vector<std::string> comparable_options() {
  std::vector<std::string> names;
  for (const Parameter& p : world_parameters()) {
    if (comparable(p)) names.emplace_back(p.flag);
  }
  return names;
}

std::string comparable_list() { return join(comparable_options()); }

Comparison parse_comparison(const std::string& spec, const scenes::Overrides& base) {
  Comparison c;
  c.spec = spec;
  if (spec.empty()) return c;
  const std::string what = "--compare " + spec + ": ";
  const std::size_t eq = spec.find('=');
  const std::string name = spec.substr(0, eq);
  const Parameter* p = find_parameter(name);
  if (p == nullptr || !comparable(*p) || p->flag != name) {
    throw UsageError(what + "'" + name + "' is not a parameter --compare takes; did you mean '" +
                     nearest_name(name, comparable_options()) + "'? Give " +
                     "PARAM=V1,V2,... with PARAM one of: " + join(comparable_options()) +
                     " (a choice alone, e.g. --compare push, compares all its values)");
  }
  c.parameter = p;
  if (base.find(p->name) != nullptr) {
    throw UsageError(what + "--" + name + " is given too; drop --" + name +
                     ": the comparison sets it for each variant");
  }
  // A setting the given push does not read (push_reads) would draw the same run in every variant.
  if (const ParameterValue* push = base.find("push"); push != nullptr && std::holds_alternative<int>(*push)) {
    const auto mode = static_cast<PushMode>(std::get<int>(*push));
    const PushReads reads = push_reads(mode);
    // The packed rows' precision matters only where the step's solver solves A lambda = b.
    const bool unread = (p->name == "solver" && !reads.solver) ||
                        (p->name == "friction_model" && !reads.friction_model) ||
                        (p->name == "warm_start" && !reads.warm_start) ||
                        (p->name == "row_precision" && !push_traits(mode).solves_system);
    if (unread) {
      throw UsageError(what + "push " + std::string(name_of(mode)) + " does not read --" + name +
                       ", so every variant would be the same run; compare another parameter, or " +
                       "drop --push to compare it under the scene's push");
    }
  }
  std::vector<std::string> texts;
  if (eq == std::string::npos) {
    if (p->type != ParameterType::choice) {
      throw UsageError(what + "give the values of " + name + " to compare, e.g. --compare " + name +
                       "=V1,V2 (" + p->allowed() + "); only a choice (" +
                       "push, solver, ...) may be named alone, to compare all its values");
    }
    for (const Choice& choice : p->choices) texts.emplace_back(choice.name);
    c.every_choice = true;
  } else {
    const std::string list = spec.substr(eq + 1);
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = list.find(',', start);
      texts.push_back(list.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
      if (comma == std::string::npos || texts.size() > kMaxVariants) break;
      start = comma + 1;
    }
  }
  const std::string how_many = "give " + std::to_string(kMinVariants) + " to " +
                               std::to_string(kMaxVariants) + " distinct values of " + name +
                               " separated by commas (" + p->allowed() + ")";
  if (texts.size() < kMinVariants || texts.size() > kMaxVariants) {
    throw UsageError(what + (texts.size() > kMaxVariants ? "more than " : "") +
                     std::to_string(std::min(texts.size(), kMaxVariants)) +
                     (texts.size() == 1 ? " value" : " values") + "; " + how_many);
  }
  for (std::size_t i = 0; i < texts.size(); ++i) {
    if (texts[i].empty()) {
      throw UsageError(what + "value " + std::to_string(i + 1) + " is empty; " + how_many);
    }
    ParameterValue v;
    try {
      v = p->parse(texts[i]);
    } catch (const std::invalid_argument& e) {
      throw UsageError(what + e.what());
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (same_value(*p, c.values[j], v)) {
        throw UsageError(what + "'" + texts[i] + "' is the same value as '" + texts[j] + "'; " +
                         how_many);
      }
    }
    c.values.push_back(v);
  }
  return c;
}

std::vector<Variant> comparison_variants(const Comparison& c, const scenes::Overrides& base) {
  if (c.parameter == nullptr) return {{base, "", ""}};
  const Parameter& p = *c.parameter;
  const std::string flag(p.flag);
  // Values shown to 6 digits, unless two would then read the same.
  bool exact = false;
  for (std::size_t i = 0; i < c.values.size() && !exact; ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (short_text(p, c.values[i], false) == short_text(p, c.values[j], false)) exact = true;
    }
  }
  std::vector<Variant> variants;
  for (const ParameterValue& v : c.values) {
    Variant variant{base, "", ""};
    variant.overrides.set(p, v);
    const std::string value = short_text(p, v, exact);
    if (p.type == ParameterType::choice) {
      const Choice* choice = p.find_choice(value);
      std::string named = choice != nullptr ? std::string(choice->title) : std::string();
      if (choice != nullptr && !choice->source.empty()) {
        named += (named.empty() ? "" : " ") + ("(" + std::string(choice->source) + ")");
      }
      variant.label = flag + " = " + value + (named.empty() ? "" : "\n" + named);
      variant.legend = value + (named.empty() ? "" : ": " + named);
    } else {
      variant.legend = flag + " = " + value + unit_text(p);
      variant.label = variant.legend + "\n" + p.label();
    }
    variants.push_back(std::move(variant));
  }
  return variants;
}

std::vector<Variant> compare_variants(const std::string& spec, const scenes::Overrides& base) {
  return comparison_variants(parse_comparison(spec, base), base);
}

std::string legend_heading(const Comparison& c) {
  if (c.parameter == nullptr) return "";
  return c.parameter->type == ParameterType::choice ? std::string(c.parameter->flag)
                                                    : c.parameter->label();
}

std::string comparison_suffix(const Comparison& c, bool overlay) {
  if (c.parameter == nullptr) return "";
  std::string s = "-compare-" + std::string(c.parameter->flag);
  if (!c.every_choice) {
    std::string values;
    for (const ParameterValue& v : c.values) {
      values += (values.empty() ? "" : "_") + c.parameter->format(v);
    }
    for (char& ch : values) {
      const bool safe = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                        (ch >= '0' && ch <= '9') || ch == '.' || ch == '+' || ch == '-' || ch == '_';
      if (!safe) ch = '-';
    }
    s += "-" + values;
  }
  return s + (overlay ? "-overlay" : "");
}

nlohmann::json comparison_json(const Comparison& c, bool overlay) {
  if (c.parameter == nullptr) return nullptr;
  nlohmann::json values = nlohmann::json::array();
  for (const ParameterValue& v : c.values) values.push_back(parameter_json(*c.parameter, v));
  return {{"spec", c.spec},
          {"parameter", c.parameter->flag},
          {"json_key", c.parameter->json_key},
          {"unit", c.parameter->unit},
          {"values", values},
          {"layout", overlay ? "overlay" : "grid"}};
}

Grid grid_layout(std::size_t variants, double aspect) {
  switch (variants) {
    case 1: return {1, 1};
    case 2: return aspect >= 1.0 ? Grid{1, 2} : Grid{2, 1};
    case 3: return {1, 3};
    case 4: return {2, 2};
    case 5:
    case 6: return {2, 3};
    case 7:
    case 8: return {2, 4};
    default: break;
  }
  throw std::invalid_argument("grid_layout: " + std::to_string(variants) + " variants; 1 to " +
                              std::to_string(kMaxVariants) + " are laid out");
}

std::array<float, 3> overlay_colour(std::size_t k) {
  static constexpr std::array<std::array<float, 3>, kMaxVariants> kColours = {{
      {0x1f / 255.0f, 0x77 / 255.0f, 0xb4 / 255.0f},  // blue
      {0xff / 255.0f, 0x7f / 255.0f, 0x0e / 255.0f},  // orange
      {0x2c / 255.0f, 0xa0 / 255.0f, 0x2c / 255.0f},  // green
      {0xd6 / 255.0f, 0x27 / 255.0f, 0x28 / 255.0f},  // red
      {0x94 / 255.0f, 0x67 / 255.0f, 0xbd / 255.0f},  // purple
      {0xbc / 255.0f, 0xbd / 255.0f, 0x22 / 255.0f},  // olive
      {0xe3 / 255.0f, 0x77 / 255.0f, 0xc2 / 255.0f},  // pink
      {0x17 / 255.0f, 0xa5 / 255.0f, 0x89 / 255.0f},  // teal
  }};
  return kColours.at(k);
}

}  // namespace cps::cli
