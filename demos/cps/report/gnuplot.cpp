#include "report/gnuplot.h"

#include "output/atomic_file.h"

#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace cps::cli {

void run_gnuplot(const std::filesystem::path& script) {
  const std::string command = "gnuplot '" + script.string() + "' 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("report: cannot start gnuplot");
  std::string output;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  const int status = pclose(pipe);
  if (status != 0) {
    throw std::runtime_error(
        "report: gnuplot failed on " + script.string() + " (exit " + std::to_string(status) +
        "): " + output.substr(0, 400) +
        (status == 127 * 256 ? "\nInstall it with: apt-get install gnuplot-nox" : ""));
  }
}

std::string gp_text(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

void draw_pictures(const std::filesystem::path& script, const std::vector<GnuplotPicture>& pictures,
                   const std::string& body, const GnuplotFraming& framing) {
  // gnuplot writes the pictures into temporaries of this run, renamed once it has succeeded.
  std::vector<std::unique_ptr<AtomicFile>> files;
  for (const GnuplotPicture& p : pictures) {
    files.push_back(std::make_unique<AtomicFile>(p.file));
    files.back()->hand_over();
  }
  std::ostringstream gp;
  for (std::size_t k = 0; k < pictures.size(); ++k) {
    gp << framing.before_each << pictures[k].terminal << "\n"
       << "set output '" << files[k]->temporary().string() << "'\n"
       << body << framing.after_each;
  }
  gp << framing.at_end;
  write_text_atomic(script, gp.str());
  run_gnuplot(script);
  for (const auto& f : files) f->commit();
}

}  // namespace cps::cli
