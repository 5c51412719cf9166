#include "report/gnuplot.h"

#include "output/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace cps::cli {
namespace {

constexpr std::size_t k_output_shown = 400;  // characters of gnuplot's output in a message

// What one gnuplot run gave: its wait status and what it printed (stdout and stderr).
struct GnuplotRun {
  int status = 0;
  std::string output;
};

// Runs `gnuplot SCRIPT` (found on PATH), stdin from /dev/null, stdout and stderr captured. The
// child is killed when this thread ends (PR_SET_PDEATHSIG), so that a killed cps leaves no
// gnuplot behind writing its temporaries after the next run removed them (output.h).
GnuplotRun gnuplot_on(const std::filesystem::path& script) {
  int out[2];
  if (::pipe2(out, O_CLOEXEC) != 0) {
    throw std::runtime_error(std::string("report: cannot start gnuplot: ") + std::strerror(errno));
  }
  const std::string path = script.string();
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(out[0]);
    ::close(out[1]);
    throw std::runtime_error(std::string("report: cannot start gnuplot: ") + std::strerror(error));
  }
  if (pid == 0) {  // only async-signal-safe calls until exec
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(126);  // cps ended before the line above
    const int null = ::open("/dev/null", O_RDONLY);
    if (null < 0 || ::dup2(null, 0) < 0 || ::dup2(out[1], 1) < 0 || ::dup2(out[1], 2) < 0) ::_exit(126);
    ::execlp("gnuplot", "gnuplot", path.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(out[1]);
  GnuplotRun run;
  std::array<char, 4096> buffer{};
  for (;;) {
    const ssize_t n = ::read(out[0], buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    run.output.append(buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(out[0]);
  while (::waitpid(pid, &run.status, 0) < 0 && errno == EINTR) {
  }
  return run;
}

// "exit N", or the signal that ended it.
std::string status_text(int status) {
  if (WIFEXITED(status)) return "exit " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + ::strsignal(WTERMSIG(status));
  return "status " + std::to_string(status);
}

std::string shown(const std::string& output) {
  return output.empty() ? std::string("(no output)") : output.substr(0, k_output_shown);
}

// Why the picture in `file` (named like its target `target`) is not a complete picture of its
// format, or "" if it is one: it must not be empty; a PNG starts with the PNG signature and ends
// with its IEND chunk, an SVG holds "<svg" and ends with "</svg>", a PDF starts with "%PDF-" and
// its last 1 KiB holds "%%EOF".
std::string incomplete(const std::filesystem::path& file, const std::filesystem::path& target) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "gnuplot wrote no file";
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) return "gnuplot wrote an empty file";
  const std::string ext = target.extension().string();
  const std::string tail = bytes.substr(bytes.size() - std::min<std::size_t>(bytes.size(), 1024));
  if (ext == ".png") {
    static const std::string signature("\x89PNG\r\n\x1a\n", 8);
    static const std::string iend("\0\0\0\0IEND\xae\x42\x60\x82", 12);
    if (bytes.rfind(signature, 0) != 0) return "not a PNG (no PNG signature)";
    if (!bytes.ends_with(iend)) return "a truncated PNG (" + std::to_string(bytes.size()) + " bytes, no IEND chunk at its end)";
  } else if (ext == ".svg") {
    if (bytes.find("<svg") == std::string::npos) return "not an SVG (no <svg)";
    const std::size_t last = bytes.find_last_not_of(" \t\r\n");
    if (last == std::string::npos || !bytes.substr(0, last + 1).ends_with("</svg>")) {
      return "a truncated SVG (" + std::to_string(bytes.size()) + " bytes, not ended by </svg>)";
    }
  } else if (ext == ".pdf") {
    if (bytes.rfind("%PDF-", 0) != 0) return "not a PDF (it does not start with %PDF-)";
    if (tail.find("%%EOF") == std::string::npos) return "a truncated PDF (" + std::to_string(bytes.size()) + " bytes, no %%EOF at its end)";
  }
  return "";
}

}  // namespace

std::string gp_text(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

void draw_pictures(const std::filesystem::path& script, const std::vector<GnuplotPicture>& pictures,
                   const std::string& body, const GnuplotFraming& framing) {
  // gnuplot writes the pictures into temporaries of this run (the AtomicFiles remove them on
  // any failure), renamed once every one of them is checked.
  std::vector<std::unique_ptr<AtomicFile>> files;
  std::string names;
  for (const GnuplotPicture& p : pictures) {
    files.push_back(std::make_unique<AtomicFile>(p.file));
    files.back()->hand_over();
    names += (names.empty() ? "" : ", ") + p.file.string();
  }
  std::ostringstream gp;
  for (std::size_t k = 0; k < pictures.size(); ++k) {
    gp << framing.before_each << pictures[k].terminal << "\n"
       << "set output " << gp_text(files[k]->temporary().string()) << "\n"
       << body << framing.after_each;
  }
  gp << framing.at_end;
  write_text_atomic(script, gp.str());
  const GnuplotRun run = gnuplot_on(script);
  if (run.status != 0) {
    const bool missing = WIFEXITED(run.status) && WEXITSTATUS(run.status) == 127;
    throw std::runtime_error("cannot write " + names + ": gnuplot failed on " + script.string() +
                             " (" + status_text(run.status) + "): " + shown(run.output) +
                             (missing ? "\nInstall it with: apt-get install gnuplot-nox" : ""));
  }
  for (std::size_t k = 0; k < pictures.size(); ++k) {
    const std::string why = incomplete(files[k]->temporary(), pictures[k].file);
    if (!why.empty()) {
      throw std::runtime_error("cannot write " + pictures[k].file.string() + ": " + why +
                               " (gnuplot ran " + script.string() + " with exit 0; its output: " +
                               shown(run.output) + "; a full disk or a file size limit?)");
    }
  }
  for (const auto& f : files) f->commit();
}

void draw_png_svg_pdf(const std::filesystem::path& dir, const std::string& stem,
                      const std::string& body, int width, int height) {
  const std::string size = std::to_string(width) + "," + std::to_string(height);
  std::ostringstream pdf_size;
  pdf_size << width / 100.0 << "in," << height / 100.0 << "in";
  draw_pictures(dir / "plots" / (stem + ".gp"),
                {{dir / (stem + ".png"), "set terminal pngcairo size " + size + " font ',10' noenhanced"},
                 {dir / (stem + ".svg"), "set terminal svg size " + size + " font ',10' noenhanced"},
                 {dir / (stem + ".pdf"), "set terminal pdfcairo size " + pdf_size.str() +
                                             " font ',10' noenhanced"}},
                body, {"", "", "unset output\n"});
}

}  // namespace cps::cli
