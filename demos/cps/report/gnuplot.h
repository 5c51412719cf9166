#pragma once
// Running gnuplot for the report's diagrams: its scripts, their text, and the pictures it writes
// through temporaries of this run (atomic_file.h).

#include <filesystem>
#include <string>
#include <vector>

namespace cps::cli {

/// Runs gnuplot on `script` (a file). Throws std::runtime_error naming the script, gnuplot's exit
/// status and the first 400 characters of its output if it fails (saying to install
/// gnuplot-nox when it is missing).
void run_gnuplot(const std::filesystem::path& script);

/// `s` as a gnuplot string: in single quotes, a quote inside doubled.
std::string gp_text(const std::string& s);

/// One picture of a script: the file it becomes and the gnuplot line that selects its terminal
/// ("set terminal pngcairo size 1100,480 font ',10' noenhanced").
struct GnuplotPicture {
  std::filesystem::path file;
  std::string terminal;
};

/// What a script puts around each picture's commands, and at its end.
struct GnuplotFraming {
  const char* before_each = "";
  const char* after_each = "";
  const char* at_end = "";
};

/// Writes `script` (atomically): per picture, framing.before_each, its terminal line, "set output
/// 'TEMPORARY'" and `body` (the drawing commands), then framing.after_each; framing.at_end last.
/// Runs gnuplot on it, then renames each temporary onto its picture's file. Throws
/// std::runtime_error if a file cannot be written or gnuplot fails (see run_gnuplot); the
/// pictures are then left as they were.
void draw_pictures(const std::filesystem::path& script, const std::vector<GnuplotPicture>& pictures,
                   const std::string& body, const GnuplotFraming& framing);

}  // namespace cps::cli
