// Runs of rows coloured for graph-coloured Gauss-Seidel (see row_colours.h).
#include "row_colours.h"

#include "buffers.h"

#include <utility>

namespace cps {
namespace {

// Rows ahead of the one being cut whose bodies colour_rows() asks for (count; 32 rows of 176
// bytes, about 5.6 KB): it reads 8 bytes of each row, and in a pile's step the rows are out of
// the cache, where each read otherwise waited for its line (docs/benchmarks.md).
constexpr std::size_t kAhead = 32;

}  // namespace

void colour_rows(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
                 int max_run, RowColours& out) {
  const auto moving = [&](int body) {
    return body == kWorldBody || bodies[static_cast<std::size_t>(body)].is_static() ? -1 : body;
  };
  out.runs.clear();
  detail::reserve_with_headroom(out.runs, rows.size());
  for (std::size_t r = 0; r < rows.size();) {
    if (r + kAhead < rows.size()) __builtin_prefetch(&rows[r + kAhead].body_a, 0, 3);
    int a = moving(rows[r].body_a);
    int b = moving(rows[r].body_b);
    if (a < 0) std::swap(a, b);
    std::size_t end = r + 1;
    while (end < rows.size() && end - r < static_cast<std::size_t>(max_run)) {
      if (end + kAhead < rows.size()) __builtin_prefetch(&rows[end + kAhead].body_a, 0, 3);
      int next_a = moving(rows[end].body_a);
      int next_b = moving(rows[end].body_b);
      if (next_a < 0) std::swap(next_a, next_b);
      if (next_a != a || next_b != b) break;
      ++end;
    }
    out.runs.push_back({static_cast<int>(r), static_cast<int>(end - r), a, b});
    r = end;
  }
  out.graph.reset(bodies.size(), StaticColours::first);
  out.colours.clear();
  detail::reserve_with_headroom(out.colours, out.runs.size());
  for (const RowColours::Run& run : out.runs) out.colours.push_back(out.graph.add(run.a, run.b));
  order_by_colour(out.colours, out.start, out.order);
}

void sweep_order(const RowColours& colours, std::vector<int>& order) {
  order.clear();
  const RowColours::Run* last = colours.runs.empty() ? nullptr : &colours.runs.back();
  detail::reserve_with_headroom(order, last == nullptr ? 0 : static_cast<std::size_t>(last->begin + last->count));
  for (int k = 0; k < ConstraintGraph::kColours; ++k) {
    const auto c = static_cast<std::size_t>(sweep_colour(k));
    for (std::size_t i = colours.start[c]; i < colours.start[c + 1]; ++i) {
      const RowColours::Run& run = colours.runs[colours.order[i]];
      for (int r = run.begin; r < run.begin + run.count; ++r) order.push_back(r);
    }
  }
}

}  // namespace cps
