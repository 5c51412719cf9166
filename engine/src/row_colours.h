#pragma once
// The sweep order of graph-coloured Gauss-Seidel (SolverKind::coloured_pgs) over the rows of
// A lambda = b: the rows are cut into runs of consecutive rows on the same two movable bodies
// (a manifold's contact and friction rows, a rod's row), the runs are coloured as Box3D and
// Box2D v3 colour their constraints (constraint_graph.h) except that a run with one movable body
// takes its first free colour (StaticColours::first: swept early, as the rows' order sweeps a
// pile's supports), and a sweep updates the runs colour by colour, the overflow first. The runs
// of one colour share no movable body, so their updates commute: any split of a colour among
// threads gives the same lambda, bit for bit.

#include "constraint_graph.h"
#include "cps/body.h"
#include "cps/constraint.h"

#include <cstddef>
#include <vector>

namespace cps {

/// The coloured order of one step's rows. Reused from step to step (allocates only to grow).
struct RowColours {
  /// Consecutive rows [begin, begin + count) on the same two movable bodies.
  struct Run {
    int begin = 0;  ///< first row
    int count = 0;  ///< rows, 1..max_run
    int a = -1;     ///< the run's movable body (index), or -1 when it has none
    int b = -1;     ///< its second movable body, or -1 (always -1 when a is)
  };
  std::vector<Run> runs;            ///< in row order
  /// Run indices colour by colour, in colour index order (sweep_order() takes the overflow
  /// first); each colour's in row order.
  std::vector<std::size_t> order;
  ColourStarts start{};             ///< colour c's runs are order[start[c], start[c + 1])
  ConstraintGraph graph;
  std::vector<int> colours;         ///< per run: its colour
};

/// Consecutive rows on the same two bodies, as ConstraintRow names them (an index or kWorldBody):
/// a manifold's contact rows, its friction rows, a rod's row. The row builder knows them from
/// the manifolds, so the cut need not read every row.
struct RowSpan {
  int body_a = kWorldBody;
  int body_b = kWorldBody;
  int count = 0;  ///< rows, >= 1
};

/// Cuts rows (c, bodies by index or kWorldBody) into runs of at most max_run (>= 1) rows on the
/// same movable bodies (a static body and the world count as none; a run's one movable body is
/// its a), colours the runs (ConstraintGraph::add) and orders them by colour, into out. bodies:
/// n, the rows' bodies. No errors (rows must name bodies below n or kWorldBody).
void colour_rows(const std::vector<ConstraintRow>& rows, const std::vector<Body>& bodies,
                 int max_run, RowColours& out);

/// colour_rows for the c = `rows` rows that `spans` lay out in order (span k's rows follow span
/// k - 1's): the same runs, colours and order as colour_rows over those rows, from the spans
/// alone (a span on the same movable bodies as the span before it continues its run). Reads
/// O(spans), not O(c). Spans must name bodies below n or kWorldBody. Throws
/// std::invalid_argument when a count is below 1 or the counts do not add up to c.
void colour_spans(const std::vector<RowSpan>& spans, std::size_t rows, const std::vector<Body>& bodies,
                  int max_run, RowColours& out);

/// The rows of `colours` in sweep order (c indices into the rows given to colour_rows), into
/// order. No errors.
void sweep_order(const RowColours& colours, std::vector<int>& order);

}  // namespace cps
