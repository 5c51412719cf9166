#pragma once
// `cps bench`: microseconds per physics step (explicit and matrix-free side by side), the cost
// growth with body count, and milliseconds per rendered frame.

namespace cps::cli {

/// Runs the benchmark tables and prints them as Markdown on stdout; progress goes to stderr.
/// quick: fewer and smaller scenes (seconds instead of minutes). Returns the exit code.
int run_bench(bool quick);

}  // namespace cps::cli
