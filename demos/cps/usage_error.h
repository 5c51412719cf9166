#pragma once
// The error of a bad command line, which every part of the command may raise (options, output
// paths, pictures, the report) and main.cpp turns into exit code 2.

#include <stdexcept>

namespace cps::cli {

/// A usage error: a bad value on the command line, with a message that names the value and what
/// is allowed. The command exits with code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace cps::cli
