#include "report/report.h"

#include "report/diagrams.h"
#include "report/markdown.h"
#include "report/reference_report.h"
#include "output/atomic_file.h"

#include <algorithm>

namespace cps::cli {

void write_report(const std::filesystem::path& dir, const std::vector<RunResult>& runs,
                  const std::map<std::string, SceneStudies>& studies,
                  const std::vector<PairRow>& pairs, const std::vector<std::string>& missing,
                  std::size_t planned, const std::string& load) {
  ReportContent c;
  c.load = load;
  c.missing = missing;
  c.planned = planned;
  c.run_count = runs.size();
  for (const RunResult& r : runs) {
    if (!c.runs.count(r.scene)) c.scenes.push_back(r.scene);
    c.runs[r.scene].push_back(&r);
  }
  const std::string title_note =
      missing.empty() ? std::string()
                      : " (INCOMPLETE: " + std::to_string(missing.size()) + " of " +
                            std::to_string(planned) + " runs missing)";
  for (const std::string& scene : c.scenes) {
    std::vector<RunResult> scene_runs;
    for (const RunResult* r : c.runs[scene]) scene_runs.push_back(*r);
    write_results(dir / (file_stem(scene) + ".csv"), scene_runs);
    for (const Measure& m : kMeasures) {
      if (draw_diagram(dir, scene, m, c.runs[scene], title_note)) c.diagrams[scene].push_back(&m);
    }
    // Solver error, the two references and energy over time (reference_report.h).
    if (const auto s = studies.find(scene); s != studies.end()) {
      c.scene_sections[scene] = write_reference_sections(dir, scene, s->second, title_note);
      c.solver_error[scene] = solver_error_medians(s->second);
    }
  }
  c.pairs = mass_ratio_table(pairs);
  write_csv(dir / "mass_ratio.csv", c.pairs);
  write_text_atomic(dir / "report.md", report_markdown(c));
}

std::vector<std::string> report_files(const std::vector<std::string>& scenes) {
  std::vector<std::string> files = {"report.md", "mass_ratio.csv"};
  for (const std::string& scene : scenes) {
    files.push_back(file_stem(scene) + ".csv");
    for (const Measure& m : kMeasures) {
      for (const char* ext : {".png", ".svg", ".pdf"}) files.push_back(file_stem(scene) + "_" + m.column + ext);
    }
  }
  for (std::string& f : reference_files(scenes)) files.push_back(std::move(f));
  return files;
}

std::vector<std::string> plot_files(const std::vector<std::string>& scenes) {
  std::vector<std::string> files;
  for (const std::string& scene : scenes) {
    for (const Measure& m : kMeasures) {
      for (const char* ext : {".dat", ".gp"}) files.push_back(file_stem(scene) + "_" + m.column + ext);
    }
  }
  for (std::string& f : reference_plot_files(scenes)) files.push_back(std::move(f));
  return files;
}

}  // namespace cps::cli
