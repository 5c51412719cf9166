#include "report/headline.h"

#include "report/csv.h"

#include <cmath>
#include <limits>

namespace cps::cli {

const RunResult* paper_run(const std::vector<const RunResult*>& runs) {
  const RunResult* base = nullptr;
  for (const RunResult* r : runs) {
    if (r->is_paper_setting()) base = r;
  }
  return base;
}

double ranked_value(const RunResult& r, const std::string& measure) {
  if (measure == "metric.recovery_time_s" && !r.diverged && r.value("metric.recovered") == 0.0) {
    return std::numeric_limits<double>::infinity();
  }
  return r.value(measure);
}

bool at_most_half(double v, double e0) {
  if (std::isinf(e0)) return std::isfinite(v);
  return v <= 0.5 * e0;
}

bool reaches(double v, double e0) {
  if (std::isinf(e0)) return std::isfinite(v);
  return v <= e0;
}

bool comparable(const RunResult& r, const RunResult& base, const std::string& measure) {
  if (measure != "trajectory_error_m") return true;
  return r.push == base.push && r.friction_model == base.friction_model;
}

const RunResult* cheapest_halving(const std::vector<const RunResult*>& runs,
                                  const std::string& measure, const RunResult& base) {
  const double e0 = ranked_value(base, measure);
  if (measure == "trajectory_error_m" && !(0.5 * e0 > base.value("reference_error_m"))) {
    return nullptr;
  }
  const RunResult* best = nullptr;
  for (const RunResult* r : runs) {
    const double t = r->value("cpu_s_per_sim_s");
    if (r->diverged || !std::isfinite(t) || !comparable(*r, base, measure)) continue;
    if (!at_most_half(ranked_value(*r, measure), e0)) continue;
    if (!best || t < best->value("cpu_s_per_sim_s")) best = r;
  }
  return best;
}

std::vector<Omission> omissions(const std::vector<const RunResult*>& runs, const std::string& measure) {
  std::vector<Omission> out;
  for (const RunResult* r : runs) {
    if (r->diverged) {
      out.push_back({r, "diverged at " + r->cell("diverged_at_s").value_or("?") + " s: " +
                            r->diverged_why.value_or("why not recorded (a CSV of an older build)")});
    } else if (std::isnan(ranked_value(*r, measure))) {
      out.push_back({r, "no value of " + measure});
    } else if (!std::isfinite(r->value("cpu_s_per_sim_s"))) {
      out.push_back({r, "no time"});
    }
  }
  return out;
}

std::string dt_text(const RunResult& r) {
  if (!r.dt_s || !(*r.dt_s > 0.0)) return "?";
  const double n = std::round(1.0 / *r.dt_s);
  if (n >= 1.0 && std::abs(n * *r.dt_s - 1.0) < 1e-5) return "1/" + number(n) + " s";
  return number(*r.dt_s) + " s";
}

}  // namespace cps::cli
