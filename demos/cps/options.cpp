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

namespace {

// A validator that accepts one of the names and hands CLI11 the enum's integer value; an unknown
// name gets "'x' is not one of: a, b".
template <class Enum>
CLI::Validator one_of(const std::vector<std::pair<std::string, Enum>>& names) {
  std::string joined;
  for (const auto& [name, value] : names) joined += (joined.empty() ? "" : ", ") + name;
  return CLI::Validator(
      [names, joined](std::string& input) -> std::string {
        for (const auto& [name, value] : names) {
          if (input == name) {
            input = std::to_string(static_cast<int>(value));
            return {};
          }
        }
        return "'" + input + "' is not one of: " + joined;
      },
      "{" + joined + "}");
}

}  // namespace

void add_world_options(CLI::App& cmd, scenes::Overrides& o) {
  cmd.add_option("--dt", o.dt, "time step (s), > 0; paper: 1/60")->check(kFinitePositive);
  cmd.add_option("--iterations", o.iterations, "PGS iterations per solve, >= 1; paper: 25")
      ->check(CLI::Range(1, 1000000));
  cmd.add_option("--beta", o.beta, "push factor constant beta (dimensionless) in [0, 1]; paper: 0.2")
      ->check(CLI::Range(0.0, 1.0));
  cmd.add_option("--friction", o.friction,
                 "friction coefficient mu (dimensionless), >= 0; scenes use 0.5")
      ->check(CLI::Range(0.0, 1e6));
  cmd.add_option("--restitution", o.restitution,
                 "coefficient of restitution eps (dimensionless) in [0, 1]; scenes use 0")
      ->check(CLI::Range(0.0, 1.0));
  cmd.add_option("--contact-margin", o.contact_margin,
                 "speculative contact distance (m), >= 0; 0 = contacts only on overlap, as in the "
                 "paper")
      ->check(CLI::Range(0.0, 1e6));
  cmd.add_option("--push", o.push,
                 "baumgarte: push factor kept in the velocity (Sec. 5); split: single frame push "
                 "factor, two solves (Sec. 8.1)")
      ->transform(one_of<PushMode>({{"baumgarte", PushMode::baumgarte}, {"split", PushMode::split}}));
  cmd.add_option("--solver", o.solver, "pgs (Sec. 7.2) or jacobi")
      ->transform(one_of<SolverKind>({{"pgs", SolverKind::pgs}, {"jacobi", SolverKind::jacobi}}));
  cmd.add_option("--friction-model", o.friction_model,
                 "fixed: the paper's limit mu m |g.n| (Sec. 5.4); coupled: mu times the contact "
                 "row's lambda")
      ->transform(one_of<FrictionModel>({
          {"fixed", FrictionModel::fixed}, {"coupled", FrictionModel::coupled}}));
  cmd.add_option("--assembly", o.assembly,
                 "explicit: sparse J, M^-1 and A = J M^-1 J^T as in the paper; matrix-free: w = "
                 "M^-1 J^T lambda per body (default; the same lambda to round-off)")
      ->transform(one_of<Assembly>({{"explicit", Assembly::explicit_matrices},
                                    {"matrix-free", Assembly::matrix_free}}));
  cmd.add_option("--rotation", o.rotation,
                 "linear: Eq. 3.2.4 then normalise; exact: the axis-angle step of Eq. 12.4.1")
      ->transform(one_of<RotationUpdate>({
          {"linear", RotationUpdate::linear}, {"exact", RotationUpdate::exact}}));
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

std::vector<Variant> compare_variants(const std::string& option, const scenes::Overrides& base) {
  if (option.empty()) return {{base, ""}};
  std::vector<Variant> v(2, Variant{base, ""});
  bool already_set = false;
  if (option == "push") {
    already_set = base.push.has_value();
    v[0].overrides.push = PushMode::baumgarte;
    v[1].overrides.push = PushMode::split;
    v[0].label = "push = baumgarte (Sec. 5.3)";
    v[1].label = "push = split (Sec. 8.1)";
  } else if (option == "solver") {
    already_set = base.solver.has_value();
    v[0].overrides.solver = SolverKind::pgs;
    v[1].overrides.solver = SolverKind::jacobi;
    v[0].label = "solver = pgs";
    v[1].label = "solver = jacobi";
  } else if (option == "friction-model") {
    already_set = base.friction_model.has_value();
    v[0].overrides.friction_model = FrictionModel::fixed;
    v[1].overrides.friction_model = FrictionModel::coupled;
    v[0].label = "friction model = fixed";
    v[1].label = "friction model = coupled";
  } else if (option == "rotation") {
    already_set = base.rotation.has_value();
    v[0].overrides.rotation = RotationUpdate::linear;
    v[1].overrides.rotation = RotationUpdate::exact;
    v[0].label = "rotation = linear (Eq. 3.2.4)";
    v[1].label = "rotation = exact (Eq. 12.4.1)";
  } else {
    throw UsageError("--compare " + option + ": allowed are push, solver, friction-model, rotation");
  }
  if (already_set) {
    throw UsageError("--compare " + option + " renders both values of --" + option +
                     "; do not set --" + option + " as well");
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
