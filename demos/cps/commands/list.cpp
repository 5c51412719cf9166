// `cps list`: the scenes with their default duration and summary.
#include "command.h"

#include "avbd_demo.h"
#include "box3d_pyramids.h"
#include "scene.h"
#include "scene_file.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <span>
#include <string>

namespace cps::cli {
namespace {

// Prints `title`, then one line per scene: name, default duration (s), summary.
void print_table(const char* title, std::span<const scenes::Scene> table) {
  std::printf("%s\n", title);
  for (const scenes::Scene& s : table) {
    std::printf("  %-22s %5.0f s  %s\n", std::string(s.name).c_str(), s.default_seconds,
                std::string(s.summary).c_str());
  }
}

}  // namespace

Command add_list(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "list", "print the scenes, example scene files and scaled families with their default duration (s) and a summary");
  return {sub, [] {
            print_table("The paper's scenes (Sec. 10; 'all'):", scenes::paper_scenes());
            print_table("Stress scenes ('stress'):", scenes::stress_scenes());
            std::printf("  %-22s %5s    the random scene with that seed (random is random_1; or "
                        "random --seed N)\n", "random_SEED", "");
            print_table("Box3D's benchmark scenes, with Box3D's world as their defaults:",
                        scenes::benchmark_scenes());
            print_table("The AVBD authors' 3D demo scenes, with the demo's solver settings as their defaults:",
                        scenes::avbd_demo_scenes());
            std::printf("Example scene files (assets/scenes, built into cps; type the name, or "
                        "'cps scene NAME' to get the file):\n");
            for (const std::string_view name : scenes::example_scene_names()) {
              const scenes::Scene* s = scenes::find_scene(name);
              std::printf("  %-22s %5.0f s  %s\n", std::string(name).c_str(), s->default_seconds,
                          std::string(s->summary).c_str());
            }
            std::printf("Scaled scenes for benchmarks, made on demand as FAMILY_N (e.g. pyramid_1000):\n");
            for (const std::string_view family : scenes::scaled_families()) {
              std::printf("  %s\n", std::string(family).c_str());
            }
            std::printf("Scene files: any PATH.json in the format of "
                        "assets/schemas/scene.schema.json (docs/scene-files.md).\n");
            std::string pushes;
            for (const Choice& c : parameter("push").choices) {
              pushes += (pushes.empty() ? "" : ", ") + std::string(c.name);
            }
            std::printf("Reports: 'cps report SCENE|all|stress' sweeps solver settings (error "
                        "against run time); 'cps report push' runs every push method (--push: "
                        "%s) on the same cases side by side.\n",
                        pushes.c_str());
            return 0;
          }};
}

}  // namespace cps::cli
