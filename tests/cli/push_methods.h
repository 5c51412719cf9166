#pragma once
// The push methods of the engine's parameter table (cps::parameter("push").choices), for the
// command-line tests whose expectations follow them (the report's sweeps, cps report push). In
// a file of its own so that test files with a local function called cps need not include the
// engine's headers. Link cps::engine and tests/cli/push_methods.cpp.

#include <string>
#include <vector>

namespace cli_test {

/// The names of the push methods, in the table's order ("baumgarte", "split", ...).
std::vector<std::string> push_method_names();

/// How many push methods the table has.
int push_methods();

/// The settings of the solve each push method reads (cps::push_reads), in the table's order.
struct Reads {
  bool solver = true;
  bool friction_model = true;
  bool warm_start = true;
};
std::vector<Reads> push_method_reads();

/// How many of them are the paper's: their source names a section of the paper ("Sec. 5.3",
/// "Sec. 8.1"), as the report's is_paper_push decides.
int paper_push_methods();

}  // namespace cli_test
