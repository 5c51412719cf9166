#include "report/measures.h"

#include "scene.h"

#include <algorithm>

namespace cps::cli {
namespace {

// The largest weight m |g| (N) among the movable bodies of `scene`; 1 N without gravity or for a
// scene this build does not know.
double largest_weight(const std::string& scene) {
  const scenes::Scene* s = scenes::find_scene(scene);
  if (!s) return 1.0;
  const scenes::Run run = scenes::make_run(*s);
  double w = 0.0;
  for (const Body& b : run.world.bodies()) {
    if (!b.is_static()) w = std::max(w, b.mass * run.world.def().gravity.norm());
  }
  return w > 0.0 ? w : 1.0;
}

}  // namespace

double floor_of(const Measure& m, const std::string& scene) {
  return m.floor_per_weight ? m.floor * largest_weight(scene) : m.floor;
}

std::string primary_measure(const std::string& scene) {
  const scenes::Scene* s = scenes::find_scene(scene);
  return std::string(s ? s->report.primary_measure : scenes::ReportTraits{}.primary_measure);
}

std::string label_of(const std::string& column) {
  for (const Measure& m : kMeasures) {
    if (column == m.column) return m.label;
  }
  return column;
}

}  // namespace cps::cli
