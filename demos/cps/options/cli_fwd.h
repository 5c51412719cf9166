#pragma once
// CLI11's classes by name only, for the headers of the command layer. CLI11 (Debian's 2.1,
// header only) costs about 10 s of compile time in every file that includes it: headers include
// this, and only the files that add options include <CLI/CLI.hpp>.

namespace CLI {
class App;
class Validator;
}  // namespace CLI
