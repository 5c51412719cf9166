#include "options/diagnostics.h"

#include <cstdio>
#include <iostream>
#include <set>

namespace cps::cli {
namespace {

struct State {
  bool quiet = false;
  bool warnings_as_errors = false;
  int warnings = 0;
  std::set<std::string, std::less<>> kinds_printed;
};

State& state() {
  static State s;
  return s;
}

}  // namespace

void add_diagnostic_flags(CLI::App& command) {
  command.add_flag("--quiet", state().quiet,
                   "no progress and no notes on stderr; each kind of warning once, as one line "
                   "with the docs page that explains it");
  command.add_flag("--warnings-as-errors", state().warnings_as_errors,
                   "exit with 3 when a warning was printed (the outputs are still written), so "
                   "that a CI job fails on it");
}

void reset_diagnostics() {
  State& s = state();
  s.quiet = false;
  s.warnings_as_errors = false;
  s.warnings = 0;
  s.kinds_printed.clear();
}

bool quiet() { return state().quiet; }

void note(const std::string& text) {
  if (!state().quiet) std::fprintf(stderr, "%s\n", text.c_str());
}

std::ostream& notes() {
  static std::ostream nothing(nullptr);  // no buffer: every write fails, silently
  return state().quiet ? nothing : std::cerr;
}

void warn(std::string_view kind, const std::string& text, const std::string& brief,
          std::string_view docs) {
  State& s = state();
  ++s.warnings;
  if (!s.quiet) {
    std::fprintf(stderr, "cps: warning: %s\n", text.c_str());
  } else if (s.kinds_printed.insert(std::string(kind)).second) {
    std::fprintf(stderr, "cps: warning: %s (see %.*s)\n", brief.c_str(),
                 static_cast<int>(docs.size()), docs.data());
  }
  std::fflush(stderr);
}

int warnings_fired() { return state().warnings; }

int exit_code_after_warnings(int code) {
  const State& s = state();
  if (code != 0 || !s.warnings_as_errors || s.warnings == 0) return code;
  std::fprintf(stderr, "cps: %d warning%s, and --warnings-as-errors: exit %d\n", s.warnings,
               s.warnings == 1 ? "" : "s", kWarningsExit);
  return kWarningsExit;
}

}  // namespace cps::cli
