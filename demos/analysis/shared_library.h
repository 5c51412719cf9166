#pragma once
// A library the analysis opens with dlopen(3) when it is first needed rather than at start-up
// (FCLIB for `export --fclib`, Siconos numerics for the exact solve): cps is not linked against
// it, so every other run skips loading it and what it brings (docs/benchmarks.md).

#include <dlfcn.h>

#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

namespace cps::analysis::detail {

/// An opened library, kept open to the end of the process.
struct SharedLibrary {
  std::string file;   ///< the name given to dlopen
  std::string named;  ///< the name for messages (says when it came from the environment)
  void* handle = nullptr;
};

/// Opens the library named by the environment variable env_var when it is set and not empty,
/// else `soname` (searched as dlopen(3) searches), RTLD_NOW | RTLD_LOCAL. what: the library in
/// messages ("FCLIB's library"); hint: what to install, appended to them. Throws
/// std::runtime_error naming the library and dlerror's reason when it cannot be opened.
inline SharedLibrary open_shared_library(const char* env_var, const char* soname,
                                         const std::string& what, const std::string& hint) {
  const char* env = std::getenv(env_var);
  const bool from_env = env != nullptr && *env != '\0';
  SharedLibrary lib;
  lib.file = from_env ? env : soname;
  lib.named = lib.file + (from_env ? std::string(" (from ") + env_var + ")" : std::string());
  lib.handle = dlopen(lib.file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (lib.handle == nullptr) {
    const char* why = dlerror();
    throw std::runtime_error("cannot open " + what + " " + lib.named + ": " +
                             (why != nullptr ? why : "dlopen failed") + hint);
  }
  return lib;
}

/// Sets f (a function pointer of the symbol's declared type) to the symbol `name` of lib.
/// Throws std::runtime_error naming the library and the symbol when it is missing.
template <typename F>
void resolve_symbol(const SharedLibrary& lib, const char* name, const std::string& what,
                    const std::string& hint, F& f) {
  dlerror();
  void* symbol = dlsym(lib.handle, name);
  if (symbol == nullptr) {
    throw std::runtime_error(what + " " + lib.named + " has no " + name + hint);
  }
  static_assert(sizeof f == sizeof symbol, "dlsym's pointer holds a function pointer");
  std::memcpy(&f, &symbol, sizeof symbol);
}

}  // namespace cps::analysis::detail
