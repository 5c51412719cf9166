#pragma once
// Running gnuplot for the report's diagrams: its scripts, their text, and the pictures it writes
// through temporaries of this run (atomic_file.h).

#include <filesystem>
#include <string>
#include <vector>

namespace cps::cli {

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
/// Each TEMPORARY is an AtomicFile of the picture's file handed over to gnuplot (atomic_file.h),
/// so the pictures must be listed in their folder's output plan (output.h). Runs gnuplot (found
/// on PATH; killed if this thread ends first) on the script, checks each picture (not empty; by
/// its extension, a .png with the PNG signature and its IEND chunk at the end, an .svg holding
/// "<svg" and ended by "</svg>", a .pdf starting with "%PDF-" with "%%EOF" in its last 1 KiB),
/// then renames every temporary onto its file. Throws std::runtime_error "cannot write PICTURE:
/// REASON" if a file cannot be written, gnuplot fails (REASON: its exit status and the first 400
/// characters of its output, and for exit 127 to install gnuplot-nox) or a picture is incomplete
/// (a full disk: gnuplot exits 0 after a failed write); no picture is then replaced and no
/// temporary is left.
void draw_pictures(const std::filesystem::path& script, const std::vector<GnuplotPicture>& pictures,
                   const std::string& body, const GnuplotFraming& framing);

/// The report's three pictures of one plot, DIR/STEM.png, .svg and .pdf, width x height px
/// (10 pt labels; the PDF at 100 px an inch, so its text sits as in the PNG), drawn from the
/// script DIR/plots/STEM.gp with draw_pictures: `body` once per picture (begin it with "reset"
/// to start each picture afresh), the PDF closed with "unset output". Throws as draw_pictures.
void draw_png_svg_pdf(const std::filesystem::path& dir, const std::string& stem,
                      const std::string& body, int width, int height);

}  // namespace cps::cli
