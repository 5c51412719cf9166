// `cps scene NAME`: any scene (paper, stress, scaled, random, example or file) written as a scene
// file (demos/scenes/scene_file.h), to stdout or to --out under the output rule (output.h).
#include "command.h"
#include "options/diagnostics.h"
#include "options/options.h"
#include "output/output.h"
#include "scene_file.h"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

namespace cps::cli {
namespace {

struct SceneOptions {
  std::string scene;
  std::string out;
  bool force = false;
};

int run_scene(const SceneOptions& o, int argc, char** argv) {
  if (o.scene == "all" || o.scene == "stress") {
    throw UsageError("scene writes one scene, not '" + o.scene + "'");
  }
  const scenes::Scene* scene = select_scenes(o.scene).front();
  const scenes::Run run = make_run_or_usage_error(*scene, {});
  const nlohmann::json file = scenes::scene_file_json(*scene, run.world);
  if (o.out.empty()) {
    std::cout << file.dump(2) << "\n";
    return 0;
  }
  const std::filesystem::path path(o.out);
  if (path.filename().empty() || path.filename() == "." || path.filename() == "..") {
    throw UsageError("--out " + o.out + ": give a file name (FILE.json), not a folder");
  }
  if (path.extension() != ".json" || path.stem().empty()) {
    throw UsageError("--out " + o.out + ": give a file name ending in .json (a scene file)");
  }
  const nlohmann::json info =
      run_info("scene", argc, argv, {{"scene", scene->name}, {"out", o.out}});
  const std::string name = path.filename().string();
  const OutputPlan plan = plan_output({.folder = path.parent_path(),
                                       .files = {name},
                                       .command = "scene",
                                       .use = FolderUse::shared,
                                       .scenes = {{name, scene_source(scene->name)}},
                                       .force = o.force});
  begin_output(plan, info);
  write_json_atomic(path, file);
  end_output(plan, info);
  notes() << "scene " << scene->name << ": " << run.world.bodies().size() << " bodies, "
            << run.world.distances().size() << " rods in " << o.out << "\n";
  return 0;
}

}  // namespace

Command add_scene(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<SceneOptions>();
  CLI::App* sub = app.add_subcommand(
      "scene", "write a scene (built-in, scaled, random or example) as a scene file (JSON)");
  sub->add_option("scene", o->scene,
                  "scene name (see 'cps list'), random_SEED, a scaled scene such as stack_10, or "
                  "the path of a scene file (.json)")
      ->required();
  sub->add_option("--out", o->out,
                  "write the scene file here (FILE.json) instead of to stdout; missing folders "
                  "are created, and the folder's run.json lists the files cps wrote there")
      ->check(kNotEmpty);
  sub->add_flag("--force", o->force,
                "let --out replace a file of that name that no earlier cps run wrote (the "
                "folder's run.json lists the files cps wrote there; those are replaced without "
                "it); any other file is never touched");
  add_seed_option(*sub, o->scene);
  return {sub, [o, argc, argv] { return run_scene(*o, argc, argv); }};
}

}  // namespace cps::cli
