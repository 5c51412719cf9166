#include "commands/system_rows.h"

#include <algorithm>
#include <cstdio>

namespace cps::cli {
namespace {

const char* kind_name(RowKind k) {
  switch (k) {
    case RowKind::contact: return "contact";
    case RowKind::friction: return "friction";
    case RowKind::distance: return "rod";
  }
  return "?";
}

}  // namespace

std::string system_rows_header(const std::string& place_column) {
  return "row,kind," + (place_column.empty() ? std::string() : place_column + ",") +
         "c_min_N,c_max_N,mu,normal_row,b_mps2,A_jj_per_kg,lambda_engine_N,lambda_exact_N";
}

std::string system_rows(const StepSystem& s, const std::string& leading,
                        const std::vector<std::string>& place, const Eigen::VectorXd& exact) {
  std::string text;
  char line[512];
  for (Eigen::Index j = 0; j < s.rows(); ++j) {
    const auto k = static_cast<std::size_t>(j);
    text += leading + std::to_string(j) + "," + kind_name(s.kinds[k]) + ",";
    if (!place.empty()) text += place.at(k) + ",";
    const int n = std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%d,%.17g,%.17g,%.17g,",
                                s.c_min[j], s.c_max[j], s.mu[j], s.normal_row[k], s.b[j],
                                s.A.coeff(j, j), s.lambda[j]);
    text.append(line, static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(sizeof line) - 1)));
    if (exact.size() == s.rows()) {
      std::snprintf(line, sizeof line, "%.17g", exact[j]);
      text += line;
    }
    text += "\n";
  }
  return text;
}

}  // namespace cps::cli
