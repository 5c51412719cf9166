// The report's headline choices (report/headline.h): the run it names is never worse than half
// the paper's value, nothing cheaper qualifies, a run that never recovered ranks last, and the
// omissions are exactly the runs it leaves out.
#include "report/headline.h"

#include "report/markdown.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <deque>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace cps::cli;

namespace {

// A run of `scene` with these settings, time (s/s) and value of `measure`; NaN for no value.
RunResult run_with(const std::string& measure, const std::string& solver, const std::string& push,
                   int iterations, int substeps, double time, double value) {
  RunResult r;
  r.scene = "stack";
  r.solver = solver;
  r.push = push;
  r.friction_model = "fixed";
  r.iterations = iterations;
  r.substeps = substeps;
  r.dt_s = 1.0 / (60.0 * substeps);
  r.cpu_s_per_sim_s = time;
  if (measure.rfind("metric.", 0) == 0) {
    if (!std::isnan(value)) r.metrics[measure.substr(7)] = value;
  } else if (measure == "trajectory_error_m") {
    if (!std::isnan(value)) r.trajectory_error_m = value;
  } else if (measure == "rod_error_max_m") {
    if (!std::isnan(value)) r.rod_error_max_m = value;
  }
  return r;
}

std::vector<const RunResult*> pointers(const std::deque<RunResult>& runs) {
  std::vector<const RunResult*> out;
  for (const RunResult& r : runs) out.push_back(&r);
  return out;
}

}  // namespace

TEST_CASE("the headline's cheapest run has at most half the paper's value and nothing cheaper "
          "does", "[report][headline]") {
  // Random sweeps of a smaller-is-better measure: whatever the values and times, the run named
  // is not diverged, at most half the paper's value, and no run that qualifies is cheaper.
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> log_value(-4.0, 1.0), log_time(-4.0, -1.0);
  std::uniform_int_distribution<int> coin(0, 5);
  const std::string measure = "rod_error_max_m";
  for (int sweep = 0; sweep < 200; ++sweep) {
    std::deque<RunResult> runs;
    runs.push_back(run_with(measure, "pgs", "baumgarte", 25, 1, 1e-3, std::pow(10.0, log_value(rng))));
    for (int k = 0; k < 30; ++k) {
      RunResult r = run_with(measure, coin(rng) < 3 ? "pgs" : "jacobi",
                             coin(rng) < 3 ? "baumgarte" : "split", 1 << coin(rng), 1 + coin(rng) / 5,
                             std::pow(10.0, log_time(rng)), std::pow(10.0, log_value(rng)));
      r.diverged = coin(rng) == 0;
      runs.push_back(r);
    }
    const std::vector<const RunResult*> ptrs = pointers(runs);
    const RunResult* base = paper_run(ptrs);
    REQUIRE(base == &runs.front());
    const double e0 = base->value(measure);
    const RunResult* best = cheapest_halving(ptrs, measure, *base);
    for (const RunResult* r : ptrs) {
      const bool qualifies = !r->diverged && r->value(measure) <= 0.5 * e0;
      if (best) {
        INFO("sweep " << sweep);
        CHECK_FALSE((qualifies && r->value("cpu_s_per_sim_s") < best->value("cpu_s_per_sim_s")));
      } else {
        CHECK_FALSE(qualifies);
      }
    }
    if (best) {
      CHECK_FALSE(best->diverged);
      CHECK(best->value(measure) <= 0.5 * e0);
    }
  }
}

TEST_CASE("a run that never recovered ranks after every run that recovered", "[report][headline]") {
  const std::string measure = "metric.recovery_time_s";
  std::deque<RunResult> runs;
  // The paper's run and a cheap one never recover; a dear one recovers at 0.4 s.
  runs.push_back(run_with(measure, "pgs", "baumgarte", 25, 1, 1e-3, std::nan("")));
  runs.push_back(run_with(measure, "jacobi", "baumgarte", 2, 1, 1e-4, std::nan("")));
  runs.push_back(run_with(measure, "pgs", "split", 64, 1, 5e-3, 0.4));
  runs[0].metrics["recovered"] = 0.0;
  runs[1].metrics["recovered"] = 0.0;
  runs[2].metrics["recovered"] = 1.0;
  CHECK(std::isinf(ranked_value(runs[0], measure)));
  CHECK(ranked_value(runs[2], measure) == 0.4);
  const std::vector<const RunResult*> ptrs = pointers(runs);
  CHECK(cheapest_halving(ptrs, measure, runs[0]) == &runs[2]);
  // Against a paper's run that recovered at 0.4 s, one that never did is not at most half.
  CHECK_FALSE(at_most_half(ranked_value(runs[1], measure), 0.4));
  CHECK(cheapest_halving(ptrs, measure, runs[2]) == nullptr);
  // Never recovering is a value, not an omission.
  CHECK(omissions(ptrs, measure).empty());
}

TEST_CASE("the trajectory error's headline compares runs of the paper's reference only, and "
          "only halvings the reference resolves", "[report][headline]") {
  const std::string measure = "trajectory_error_m";
  std::deque<RunResult> runs;
  runs.push_back(run_with(measure, "pgs", "baumgarte", 25, 1, 1e-3, 0.1));
  runs.push_back(run_with(measure, "jacobi", "split", 4, 1, 1e-4, 0.001));      // another reference
  runs.push_back(run_with(measure, "pgs", "baumgarte", 25, 4, 4e-3, 0.02));     // same reference
  for (RunResult& r : runs) r.reference_error_m = 0.01;
  const std::vector<const RunResult*> ptrs = pointers(runs);
  CHECK(cheapest_halving(ptrs, measure, runs[0]) == &runs[2]);
  // A reference whose own error is above half the paper's value resolves no halving.
  for (RunResult& r : runs) r.reference_error_m = 0.06;
  CHECK(cheapest_halving(ptrs, measure, runs[0]) == nullptr);
  // Nor one whose own error is unknown (its runs at 4, 8 and 16 substeps do not converge),
  // however small its distance at half its substeps.
  for (RunResult& r : runs) {
    r.reference_error_m.reset();
    r.reference_check_m = 1e-6;
  }
  CHECK(cheapest_halving(ptrs, measure, runs[0]) == nullptr);
}

TEST_CASE("the omissions are exactly the diverged runs and the runs without a value or time",
          "[report][headline]") {
  const std::string measure = "rod_error_max_m";
  std::deque<RunResult> runs;
  runs.push_back(run_with(measure, "pgs", "baumgarte", 25, 1, 1e-3, 0.01));
  runs.push_back(run_with(measure, "jacobi", "baumgarte", 16, 1, 1e-3, 5.0));
  runs.back().diverged = true;
  runs.back().diverged_at_s = 1.25;
  runs.back().diverged_why = "rod error 5 m past the largest body's size 1 m";
  runs.push_back(run_with(measure, "jacobi", "split", 16, 1, 1e-3, std::nan("")));
  runs.push_back(run_with(measure, "pgs", "split", 4, 1, std::nan(""), 0.02));
  runs.back().cpu_s_per_sim_s.reset();
  runs.push_back(run_with(measure, "jacobi", "baumgarte", 1, 1, 1e-3, 0.2));
  runs.back().diverged = true;  // a CSV of an older build: no diverged_why
  runs.back().diverged_at_s = 0.5;
  const std::vector<Omission> left = omissions(pointers(runs), measure);
  REQUIRE(left.size() == 4u);
  CHECK(left[0].run == &runs[1]);
  CHECK(left[0].why == "diverged at 1.25 s: rod error 5 m past the largest body's size 1 m");
  CHECK(left[1].run == &runs[2]);
  CHECK(left[1].why == "no value of rod_error_max_m");
  CHECK(left[2].run == &runs[3]);
  CHECK(left[2].why == "no time");
  CHECK(left[3].run == &runs[4]);
  CHECK(left[3].why.find("why not recorded") != std::string::npos);
}

TEST_CASE("report.md gives a run's dt as a fraction where it is one", "[report][headline]") {
  RunResult r;
  CHECK(dt_text(r) == "?");
  r.dt_s = 0.0166667;  // 1/60 s at the CSV's 6 digits
  CHECK(dt_text(r) == "1/60 s");
  r.dt_s = 0.00166667;
  CHECK(dt_text(r) == "1/600 s");
  r.dt_s = 0.003;
  CHECK(dt_text(r) == "0.003 s");
}

TEST_CASE("the headline says so when its cheapest run's solver diverges on the paper run's steps",
          "[report][headline]") {
  const std::string measure = "trajectory_error_m";
  std::deque<RunResult> runs;
  runs.push_back(run_with(measure, "pgs", "baumgarte", 25, 1, 1e-3, 0.03));
  runs.push_back(run_with(measure, "jacobi", "baumgarte", 25, 4, 3e-3, 0.004));
  runs.back().residual_max_N = 516.0;
  for (RunResult& r : runs) r.reference_error_m = 0.001;
  ReportContent c;
  c.scenes = {"stack"};
  c.runs["stack"] = pointers(runs);
  c.run_count = runs.size();
  const auto headline_row = [&] {
    const std::string md = report_markdown(c);
    const std::size_t at = md.find("| stack | ");
    REQUIRE(at != std::string::npos);
    return md.substr(at, md.find('\n', at) - at);
  };
  // Jacobi's sweeps end further from the solutions than lambda = 0 (relative error 1) at 25
  // sweeps on the paper run's steps: the row names the halving run and says so.
  c.solver_error["stack"]["jacobi"] = {{1, 0.95}, {5, 0.85}, {25, 8.7}, {100, 8.1}};
  const std::string diverging = headline_row();
  CHECK(diverging.find("jacobi, baumgarte, fixed, 25 it, 4 substeps") != std::string::npos);
  CHECK(diverging.find("jacobi's sweeps diverge on the paper run's steps") != std::string::npos);
  CHECK(diverging.find("8.7 |lambda*| at 25 sweeps") != std::string::npos);
  CHECK(diverging.find("up to 516 N") != std::string::npos);
  // Sweeps that converge (under 1 at 25), or a count past the run's iterations (100 > 25): no note.
  c.solver_error["stack"]["jacobi"] = {{1, 0.95}, {25, 0.7}, {100, 8.1}};
  const std::string converging = headline_row();
  CHECK(converging.find("jacobi, baumgarte, fixed, 25 it, 4 substeps") != std::string::npos);
  CHECK(converging.find("diverge") == std::string::npos);
}
