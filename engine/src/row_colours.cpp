// Runs of rows coloured for graph-coloured Gauss-Seidel (see row_colours.h).
#include "row_colours.h"

#include "buffers.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace cps {
namespace {

// Rows ahead of the one being cut whose bodies colour_rows() asks for (count; 32 rows of 176
// bytes, about 5.6 KB): it reads 8 bytes of each row, and in a pile's step the rows are out of
// the cache, where each read otherwise waited for its line (docs/benchmarks.md).
constexpr std::size_t kAhead = 32;

// A body as a run counts it: its index when it moves, else -1 (a static body or the world).
int moving(int body, const std::vector<Body>& bodies) {
  return body == kWorldBody || bodies[static_cast<std::size_t>(body)].is_static() ? -1 : body;
}

// Appends rows [begin, begin + count) on the movable bodies (a, b) (a run's order: a is -1
// only when b is) to `runs`: they continue the last run while it is on the same pair and
// shorter than max_run, then fill new runs of max_run rows, the last one shorter.
inline void extend_runs(int begin, int count, int a, int b, int max_run,
                        std::vector<RowColours::Run>& runs) {
  if (!runs.empty()) {
    RowColours::Run& last = runs.back();
    if (last.a == a && last.b == b && last.count < max_run) {
      const int taken = std::min(count, max_run - last.count);
      last.count += taken;
      begin += taken;
      count -= taken;
    }
  }
  for (; count > 0;) {
    const int taken = std::min(count, max_run);
    runs.push_back({begin, taken, a, b});
    begin += taken;
    count -= taken;
  }
}

// Colours out.runs (ConstraintGraph::add, in order) and orders them by colour.
void colour_runs(const std::vector<Body>& bodies, RowColours& out) {
  out.graph.reset(bodies.size(), StaticColours::first);
  out.colours.clear();
  detail::reserve_with_headroom(out.colours, out.runs.size());
  for (const RowColours::Run& run : out.runs) out.colours.push_back(out.graph.add(run.a, run.b));
  order_by_colour(out.colours, out.start, out.order);
}

}  // namespace

void colour_rows(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
                 int max_run, RowColours& out) {
  out.runs.clear();
  detail::reserve_with_headroom(out.runs, rows.size());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (r + kAhead < rows.size()) __builtin_prefetch(&rows[r + kAhead].body_a, 0, 3);
    int a = moving(rows[r].body_a, bodies);
    int b = moving(rows[r].body_b, bodies);
    if (a < 0) std::swap(a, b);
    extend_runs(static_cast<int>(r), 1, a, b, max_run, out.runs);
  }
  colour_runs(bodies, out);
}

void colour_spans(const std::vector<RowSpan>& spans, std::size_t rows, const std::vector<Body>& bodies,
                  int max_run, RowColours& out) {
  std::size_t covered = 0;
  for (const RowSpan& span : spans) {
    if (span.count < 1) {
      throw std::invalid_argument("colour_spans: a span of " + std::to_string(span.count) +
                                  " rows; a span has at least 1");
    }
    covered += static_cast<std::size_t>(span.count);
  }
  if (covered != rows) {
    throw std::invalid_argument("colour_spans: the spans cover " + std::to_string(covered) +
                                " rows, not the " + std::to_string(rows) + " rows given");
  }
  out.runs.clear();
  detail::reserve_with_headroom(out.runs, spans.size() + rows / static_cast<std::size_t>(max_run));
  int begin = 0;
  for (const RowSpan& span : spans) {
    int a = moving(span.body_a, bodies);
    int b = moving(span.body_b, bodies);
    if (a < 0) std::swap(a, b);
    extend_runs(begin, span.count, a, b, max_run, out.runs);
    begin += span.count;
  }
  colour_runs(bodies, out);
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
