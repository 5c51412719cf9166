#pragma once
// What cps says on stderr besides its errors: progress, notes and warnings, and the two flags of
// every command that steps that govern them: --quiet and --warnings-as-errors.

#include <CLI/CLI.hpp>

#include <ostream>
#include <string>
#include <string_view>

namespace cps::cli {

/// The exit code of a command that ended well but warned under --warnings-as-errors.
inline constexpr int kWarningsExit = 3;

/// Adds --quiet and --warnings-as-errors to `command` (a command that steps). Process-wide: the
/// command parsed sets them. No errors.
void add_diagnostic_flags(CLI::App& command);

/// Clears what the diagnostics hold (--quiet, --warnings-as-errors, the warnings printed and
/// their kinds), so that a process running several command lines (run_command) judges each on
/// its own. No errors.
void reset_diagnostics();

/// --quiet: no progress, no notes, each kind of warning once as one line (warn). No errors.
bool quiet();

/// Prints `text` (one line, no newline) on stderr unless quiet(): what a command reports of its
/// work besides its outputs ("render: the context", "trace: 301 rows"). No errors.
void note(const std::string& text);

/// std::cerr, or under --quiet a stream that writes nothing: for notes written with <<. No errors.
std::ostream& notes();

/// Prints a warning on stderr as "cps: warning: TEXT" and counts it. Under --quiet only the
/// first warning of each `kind` ("energy_rise", "divergence", "ffmpeg") is printed, as one line:
/// "cps: warning: BRIEF (see DOCS)", where `brief` is one line and `docs` the docs page (and
/// anchor) that explains it. No errors.
void warn(std::string_view kind, const std::string& text, const std::string& brief,
          std::string_view docs);

/// The warnings warn() counted in this process (count).
int warnings_fired();

/// The exit code for a command that returned `code`: kWarningsExit when `code` is 0, warnings
/// fired and --warnings-as-errors was given (after a line on stderr saying why), else `code`.
int exit_code_after_warnings(int code);

}  // namespace cps::cli
