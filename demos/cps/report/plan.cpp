#include "report/plan.h"

#include "options/options.h"

#include <charconv>
#include <optional>
#include <sstream>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;

// The value of a choice parameter called `text` in a run id, or std::nullopt.
template <class Enum>
std::optional<Enum> choice_of(const char* parameter_name, const std::string& text) {
  const Choice* c = parameter(parameter_name).find_choice(text);
  if (c == nullptr) return std::nullopt;
  return static_cast<Enum>(c->value);
}

bool has_friction(const scenes::Scene& scene) { return scene.world_def().friction > 0.0; }

// True if `scene` is one of the paper's scenes (its table, scenes::paper_scenes()).
bool is_paper_scene(const scenes::Scene& scene) {
  for (const scenes::Scene& s : scenes::paper_scenes()) {
    if (s.name == scene.name) return true;
  }
  return false;
}

// The usage error of a malformed run id: what is wrong and the form ids take.
UsageError bad_id(const std::string& id, const std::string& why) {
  const auto names = [](const char* parameter_name) {
    std::string list;
    for (const Choice& c : parameter(parameter_name).choices) {
      list += (list.empty() ? "" : "|") + std::string(c.name);
    }
    return list;
  };
  return UsageError("run id '" + id + "': " + why + "; expected scene." + names("solver") + "." +
                    names("push") + "." + names("friction_model") +
                    ".itN.ssM, optionally followed by .wsF, a warm start factor F in [0, 1]; or "
                    "a study's id ('cps report SCENE --list-runs' lists every id of a sweep)");
}

// Splits the warm start factor off an id: ".wsF" right after the ".ssM" part (F may hold a dot).
// Returns the id without it; `warm_start` is F, or 0 without it.
std::string split_warm_start(const std::string& id, double& warm_start) {
  warm_start = 0.0;
  const std::size_t ws = id.rfind(".ws");
  if (ws == std::string::npos) return id;
  const std::size_t ss = id.rfind(".ss", ws);
  const bool after_ss = ss != std::string::npos && ss + 3 < ws &&
                        id.find_first_not_of("0123456789", ss + 3) == ws;
  if (!after_ss) return id;
  const std::string f = id.substr(ws + 3);
  const char* first = f.c_str();
  const char* last = first + f.size();
  const auto [end, ec] = std::from_chars(first, last, warm_start, std::chars_format::fixed);
  if (first == last || ec != std::errc() || end != last || !(warm_start >= 0.0) ||
      !(warm_start <= 1.0)) {
    throw bad_id(id, "'ws" + f + "' is not a warm start factor in [0, 1]");
  }
  return id.substr(0, ws);
}

// The six dot-separated parts of an id without its warm start factor: the last five are the
// settings, the scene is what comes before them (scene names may hold a dot:
// pendulum_wave_dt_0.1).
std::vector<std::string> id_parts(const std::string& id, const std::string& rest) {
  std::vector<std::string> parts;
  std::stringstream s(rest);
  for (std::string part; std::getline(s, part, '.');) parts.push_back(part);
  if (parts.size() < 6) throw bad_id(id, "it has " + std::to_string(parts.size()) + " parts, not 6");
  while (parts.size() > 6) {
    parts[0] += "." + parts[1];
    parts.erase(parts.begin() + 1);
  }
  return parts;
}

// A whole decimal count after `prefix` in a part of `id`, nothing else ("it4294967297" and
// "it1x" are refused), in [1, most].
int id_count(const std::string& id, const std::string& part, const char* prefix, int most) {
  if (part.rfind(prefix, 0) != 0) throw bad_id(id, "'" + part + "' does not start with " + prefix);
  int n = 0;
  const char* first = part.c_str() + 2;
  const char* last = part.c_str() + part.size();
  const auto [end, ec] = std::from_chars(first, last, n);
  if (first == last || ec != std::errc() || end != last || n < 1 || n > most) {
    throw bad_id(id, "'" + part + "' is not a count in [1, " + std::to_string(most) + "]");
  }
  return n;
}

}  // namespace

std::string run_id(const std::string& scene, const std::string& solver, const std::string& push,
                   const std::string& friction_model, int iterations, int substeps,
                   double warm_start) {
  return scene + "." + solver + "." + push + "." + friction_model + ".it" +
         std::to_string(iterations) + ".ss" + std::to_string(substeps) +
         (warm_start != 0.0 ? ".ws" + shortest_decimal(warm_start) : std::string());
}

std::string RunSpec::id() const {
  return run_id(scene, std::string(name_of(solver)), std::string(name_of(push)),
                std::string(name_of(friction_model)), iterations, substeps, warm_start);
}

RunSpec RunSpec::parse(const std::string& id) {
  RunSpec r;
  const std::vector<std::string> parts = id_parts(id, split_warm_start(id, r.warm_start));
  r.scene = parts[0];
  if (!scenes::find_scene(r.scene)) throw bad_id(id, "unknown scene");
  const auto solver = choice_of<SolverKind>("solver", parts[1]);
  if (!solver) throw bad_id(id, "unknown solver '" + parts[1] + "'");
  const auto push = choice_of<PushMode>("push", parts[2]);
  if (!push) throw bad_id(id, "unknown push '" + parts[2] + "'");
  const auto friction_model = choice_of<FrictionModel>("friction_model", parts[3]);
  if (!friction_model) throw bad_id(id, "unknown friction model '" + parts[3] + "'");
  r.solver = *solver;
  r.push = *push;
  r.friction_model = *friction_model;
  r.iterations = id_count(id, parts[4], "it", static_cast<int>(parameter("iterations").max));
  r.substeps = id_count(id, parts[5], "ss", kMaxSubsteps);
  check_steps("run " + id, r.scene_def().report_horizon_s(),
              std::get<double>(*r.overrides().find("dt")));
  return r;
}

const scenes::Scene& RunSpec::scene_def() const {
  const scenes::Scene* s = scenes::find_scene(scene);
  if (!s) throw UsageError("report: unknown scene '" + scene + "'");
  return *s;
}

double RunSpec::horizon_s() const { return scene_def().report_horizon_s(quick); }

scenes::Overrides RunSpec::overrides() const {
  const scenes::Scene& s = scene_def();
  scenes::Overrides o;
  o.set("solver", solver);
  o.set("push", push);
  o.set("friction_model", friction_model);
  o.set("iterations", iterations);
  o.set("warm_start", warm_start);
  o.set("dt", is_paper_scene(s) ? 1.0 / (60.0 * substeps) : s.world_def().dt / substeps);
  return o;
}

bool is_paper_push(const Choice& push) { return push.in_paper; }

std::vector<RunSpec> plan_runs(const std::vector<const scenes::Scene*>& scenes, bool quick) {
  const std::vector<int> iterations =
      quick ? std::vector<int>{1, 4, 16, 25, 64} : std::vector<int>{1, 2, 4, 8, 16, 25, 32, 64, 128, 256};
  const std::vector<int> substeps = quick ? std::vector<int>{4} : std::vector<int>{2, 4, 8, 16};
  std::vector<RunSpec> runs;
  for (const scenes::Scene* scene : scenes) {
    const std::string name(scene->name);
    std::vector<FrictionModel> frictions = {FrictionModel::fixed};
    if (!quick && has_friction(*scene)) frictions.push_back(FrictionModel::coupled);
    for (const FrictionModel f : frictions) {
      for (const Choice& c : parameter("push").choices) {
        const auto p = static_cast<PushMode>(c.value);
        // A setting the push does not read would repeat its runs (see the declaration).
        const PushReads reads = push_reads(p);
        if (f != FrictionModel::fixed && !reads.friction_model) continue;
        for (const SolverKind s : {SolverKind::pgs, SolverKind::jacobi}) {
          if (s != SolverKind::pgs && !reads.solver) continue;
          // The quick sweep runs Jacobi for the paper's push methods only (see the declaration).
          if (quick && s != SolverKind::pgs && !is_paper_push(c)) continue;
          for (const int it : iterations) runs.push_back({name, s, p, f, it, 1});
          for (const int ss : substeps) runs.push_back({name, s, p, f, kPaperIterations, ss});
        }
        // Warm starting, PGS only (see the declaration); the quick sweep at the paper's push.
        if (!reads.warm_start || (quick && p != PushMode::baumgarte)) continue;
        for (const double w : kReportWarmStarts) {
          if (quick) {
            for (const int it : kQuickWarmIterations) runs.push_back({name, SolverKind::pgs, p, f, it, 1, w});
          } else {
            for (const int it : iterations) runs.push_back({name, SolverKind::pgs, p, f, it, 1, w});
          }
        }
      }
    }
  }
  for (RunSpec& r : runs) r.quick = quick;
  return runs;
}

std::string file_stem(const std::string& scene) {
  if (!scene.ends_with(".json")) return scene;
  try {
    if (const scenes::Scene* s = scenes::find_scene(scene)) return std::string(scenes::output_name(*s));
  } catch (const std::invalid_argument&) {
    // A scene file that is gone (a merged CSV's): its stem.
  }
  return fs::path(scene).stem().string();
}

std::string run_file_name(const RunSpec& spec) {
  return file_stem(spec.scene) + spec.id().substr(spec.scene.size()) + ".csv";
}

std::vector<std::string> scene_names(const std::vector<const scenes::Scene*>& scenes) {
  std::vector<std::string> names;
  for (const scenes::Scene* s : scenes) names.emplace_back(s->name);
  return names;
}

}  // namespace cps::cli
