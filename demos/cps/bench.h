#pragma once
// `cps bench`: microseconds per physics step (explicit and matrix-free side by side), the cost
// growth with body count, and milliseconds per rendered frame.

namespace cps::cli {

/// Runs the benchmark tables and prints them as Markdown on stdout; progress goes to stderr.
/// quick: fewer and smaller scenes (seconds instead of minutes), one end-to-end rendering run per
/// scene instead of three. rendering_only: only the rendering table (ms per frame: physics, draw,
/// PNG encoding, the real pipeline end to end). Returns the exit code (2 for rendering_only in a
/// build without the renderer).
int run_bench(bool quick, bool rendering_only = false);

}  // namespace cps::cli
