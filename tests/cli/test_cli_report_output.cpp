// cps report --merge and the output rule, run as a user runs it: gnuplot's plots on a full disk
// (a file size limit: RLIMIT_FSIZE with SIGXFSZ ignored, so a write past it fails with EFBIG as
// one on a full disk fails with ENOSPC), a gnuplot that fails, the temporaries of a killed run,
// and the merge's refusals of duplicate runs, non-finite cells and too much data.
#include "cli_support.h"
#include "report/csv.h"
#include "report/reference_report.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace {

using cli_test::Result;
using cli_test::run_cps;
using cli_test::slurp;

fs::path fresh_dir(const std::string& name) { return cli_test::fresh_dir("cps_cli_report_output_" + name); }

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

// Two runs of the stack's sweep (their CSVs in dir/runs): a merge of them draws three diagrams.
// Two runs of the stack's sweep and its three studies (their sections' pictures), into DIR/runs.
void two_runs(const fs::path& dir) {
  for (const char* id : {"stack.pgs.split.fixed.it4.ss1", "stack.jacobi.split.fixed.it4.ss1",
                         "stack.solver_error", "stack.references", "stack.energy"}) {
    REQUIRE(run_cps(std::string("report stack --run ") + id + " --out runs", dir).exit_code == 0);
  }
}

// run_cps in a child process of its own, with the largest resident memory (MiB, rounded up to
// 255 at most) that any process it waited for had: cps's peak, apart from this test's others.
std::pair<Result, int> run_cps_peak(const std::string& args, const fs::path& dir) {
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    const Result r = run_cps(args, dir);
    std::ofstream(dir / "peak_result.txt") << r.exit_code << "\n" << r.err;
    rusage usage{};
    ::getrusage(RUSAGE_CHILDREN, &usage);
    ::_exit(static_cast<int>(std::min<long>(255, (usage.ru_maxrss + 1023) / 1024)));
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  REQUIRE(WIFEXITED(status));
  std::ifstream in(dir / "peak_result.txt");
  Result r;
  in >> r.exit_code;
  r.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  fs::remove(dir / "peak_result.txt");
  return {r, WEXITSTATUS(status)};
}

// The names of the files in `folder` (not below it) that end with `suffix`.
std::vector<std::string> files_ending(const fs::path& folder, const std::string& suffix) {
  std::vector<std::string> names;
  if (!fs::is_directory(folder)) return names;
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      names.push_back(name);
    }
  }
  return names;
}

// The environment prefix of run_cps that limits every file cps (and gnuplot) writes to `bytes`.
std::string file_size_limit(int bytes) {
  return "trap '' XFSZ; prlimit --fsize=" + std::to_string(bytes);
}

// A fake gnuplot in dir/fake (put first on PATH) running `body` (sh; $1 is the script).
std::string fake_gnuplot(const fs::path& dir, const std::string& body) {
  const fs::path fake = dir / "fake";
  fs::create_directories(fake);
  write_text(fake / "gnuplot", "#!/bin/sh\n" + body);
  fs::permissions(fake / "gnuplot", fs::perms::owner_all);
  return "PATH='" + fake.string() + "':\"$PATH\"";
}

// sh lines that make each "set output 'FILE'" of the script $1 hold `content`.
std::string each_output(const std::string& content) {
  return "sed -n \"s/^set output '\\(.*\\)'$/\\1/p\" \"$1\" | while IFS= read -r f; do "
         "printf '" + content + "' > \"$f\"; done\n";
}

// As each_output, with the content (printf formats) by the file's extension.
std::string each_output_by_type(const std::string& png, const std::string& svg, const std::string& pdf) {
  return "sed -n \"s/^set output '\\(.*\\)'$/\\1/p\" \"$1\" | while IFS= read -r f; do case $f in "
         "*.png.*) printf '" + png + "' > \"$f\";; *.svg.*) printf '" + svg + "' > \"$f\";; "
         "*.pdf.*) printf '" + pdf + "' > \"$f\";; esac; done\n";
}

// True once process `pid` is gone or a zombie.
bool ended(pid_t pid) {
  if (::kill(pid, 0) != 0 && errno == ESRCH) return true;
  const std::string stat = slurp("/proc/" + std::to_string(pid) + "/stat");
  const std::size_t paren = stat.rfind(')');
  return paren == std::string::npos || (paren + 2 < stat.size() && stat[paren + 2] == 'Z');
}

// Waits (up to `limit`, polling) until `done` holds; returns whether it did.
template <class Done>
bool wait_for(Done&& done, std::chrono::seconds limit) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

std::string host_name() {
  char name[256] = {};
  REQUIRE(::gethostname(name, sizeof name - 1) == 0);
  return name;
}

// A process id that surely ended: a child that exited and was reaped.
pid_t ended_pid() {
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) ::_exit(0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return pid;
}

// The pictures of each kind a report of the stack draws: three measures' diagrams and the
// reference sections' (reference_report.h).
constexpr std::size_t kStackPictures = 3 + std::size(cps::cli::kReferenceParts);

}  // namespace

TEST_CASE("report --merge on a full disk names the plot and leaves no plot, part or temporary",
          "[cli][report][output]") {
  const fs::path dir = fresh_dir("full");
  two_runs(dir);
  // Unlimited, every picture is larger than the limit below.
  REQUIRE(run_cps("report --merge runs --out whole", dir).exit_code == 1);  // INCOMPLETE
  for (const char* ext : {".png", ".svg", ".pdf"}) {
    REQUIRE(files_ending(dir / "whole", ext).size() == kStackPictures);
    for (const std::string& name : files_ending(dir / "whole", ext)) {
      INFO(name);
      CHECK(fs::file_size(dir / "whole" / name) > 12288);
    }
  }
  const Result r = run_cps("report --merge runs --out out", dir, file_size_limit(12288));
  INFO(r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("cannot write out/stack_trajectory_error_m.png: a truncated PNG") != std::string::npos);
  for (const char* ext : {".png", ".svg", ".pdf", ".tmp"}) {
    INFO(ext);
    CHECK(files_ending(dir / "out", ext).empty());
    CHECK(files_ending(dir / "out/plots", ext).empty());
  }
  // The rerun with room writes them all.
  CHECK(run_cps("report --merge runs --out out", dir).exit_code == 1);
  CHECK(files_ending(dir / "out", ".pdf").size() == kStackPictures);
  fs::remove_all(dir);
}

TEST_CASE("report --merge checks gnuplot's status and its pictures before they take their names",
          "[cli][report][output]") {
  const fs::path dir = fresh_dir("fake");
  two_runs(dir);
  SECTION("gnuplot fails after writing parts: its reason is named, no part is kept") {
    const std::string path = fake_gnuplot(dir, each_output("partial") +
                                                    "echo 'fake gnuplot: no room for the plot'\n"
                                                    "exit 1\n");
    const Result r = run_cps("report --merge runs --out out", dir, path);
    INFO(r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("out/stack_trajectory_error_m.png") != std::string::npos);
    CHECK(r.err.find("exit 1") != std::string::npos);
    CHECK(r.err.find("fake gnuplot: no room for the plot") != std::string::npos);
  }
  SECTION("gnuplot exits 0 with empty files (as on a full disk)") {
    const std::string path = fake_gnuplot(dir, each_output("") + "exit 0\n");
    const Result r = run_cps("report --merge runs --out out", dir, path);
    INFO(r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("cannot write out/stack_trajectory_error_m.png: gnuplot wrote an empty file") !=
          std::string::npos);
  }
  SECTION("gnuplot exits 0 with files that are not pictures") {
    const std::string path = fake_gnuplot(dir, each_output("%%PDF-1.5") + "exit 0\n");
    const Result r = run_cps("report --merge runs --out out", dir, path);
    INFO(r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("cannot write out/stack_trajectory_error_m.png: not a PNG") != std::string::npos);
  }
  // A whole PNG (signature, IEND), then an SVG or a PDF cut short.
  const std::string png = "\\211PNG\\r\\n\\032\\n\\0\\0\\0\\0IEND\\256B\\140\\202";
  SECTION("gnuplot exits 0 with an SVG cut short") {
    const std::string path = fake_gnuplot(
        dir, each_output_by_type(png, "<svg width=\"1100\"><g>", "%%PDF-1.5 ... %%%%EOF") + "exit 0\n");
    const Result r = run_cps("report --merge runs --out out", dir, path);
    INFO(r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("cannot write out/stack_trajectory_error_m.svg: a truncated SVG") != std::string::npos);
  }
  SECTION("gnuplot exits 0 with a PDF cut short") {
    const std::string path = fake_gnuplot(
        dir, each_output_by_type(png, "<svg width=\"1100\"></svg>\\n", "%%PDF-1.5 1 0 obj") + "exit 0\n");
    const Result r = run_cps("report --merge runs --out out", dir, path);
    INFO(r.err);
    CHECK(r.exit_code == 1);
    CHECK(r.err.find("cannot write out/stack_trajectory_error_m.pdf: a truncated PDF") != std::string::npos);
  }
  for (const char* ext : {".png", ".svg", ".pdf", ".tmp"}) {
    INFO(ext);
    CHECK(files_ending(dir / "out", ext).empty());
  }
  fs::remove_all(dir);
}

TEST_CASE("the temporaries of a killed report --merge are removed by the next merge, nothing else",
          "[cli][report][output]") {
  const fs::path dir = fresh_dir("leftover");
  two_runs(dir);
  // A merge killed while it wrote: run.json lists it unfinished (a process that ended) with its
  // files, and their temporaries remain, in OUT and OUT/plots.
  const std::string token = "0123456789abcdef";
  const std::vector<std::string> main_files = {"report.md", "stack.csv", "stack_trajectory_error_m.png",
                                               "stack_trajectory_error_m.svg", "stack_trajectory_error_m.pdf"};
  const std::vector<std::string> plot_files = {"stack_trajectory_error_m.dat", "stack_trajectory_error_m.gp"};
  const pid_t dead = ended_pid();
  const auto killed_run = [&](const fs::path& folder, const std::vector<std::string>& files) {
    fs::create_directories(folder);
    const nlohmann::json run = {{"run_token", token}, {"pid", dead}, {"host", host_name()},
                                {"start", 0}, {"files", files}};
    write_text(folder / "run.json", nlohmann::json{{"tool", "cps"}, {"complete", false}, {"files", files},
                                                   {"unfinished_runs", {run}}}.dump(2));
    for (const std::string& f : files) write_text(folder / (f + "." + token + ".tmp"), "part");
  };
  killed_run(dir / "out", main_files);
  killed_run(dir / "out/plots", plot_files);
  // Files that look alike but are not that run's: kept.
  const std::vector<std::string> foreign = {"notes.txt", "stack_trajectory_error_m.png.fedcba9876543210.tmp",
                                            "other.png." + token + ".tmp"};
  for (const std::string& f : foreign) write_text(dir / "out" / f, "mine");

  const Result r = run_cps("report --merge runs --out out", dir);
  INFO(r.err);
  CHECK(r.exit_code == 1);  // INCOMPLETE
  for (const std::string& f : main_files) CHECK_FALSE(fs::exists(dir / "out" / (f + "." + token + ".tmp")));
  for (const std::string& f : plot_files) CHECK_FALSE(fs::exists(dir / "out/plots" / (f + "." + token + ".tmp")));
  for (const std::string& f : foreign) CHECK(slurp(dir / "out" / f) == "mine");
  CHECK(files_ending(dir / "out", ".tmp").size() == 2);  // the two foreign ones
  CHECK(files_ending(dir / "out/plots", ".tmp").empty());
  CHECK(fs::file_size(dir / "out/stack_trajectory_error_m.pdf") > 1000);
  const nlohmann::json manifest = nlohmann::json::parse(slurp(dir / "out/run.json"));
  CHECK(manifest["complete"] == true);
  CHECK(manifest["unfinished_runs"].empty());
  fs::remove_all(dir);
}

TEST_CASE("a killed report --merge leaves no gnuplot writing, and the next merge removes its "
          "temporaries", "[cli][report][output]") {
  const fs::path dir = fresh_dir("killed");
  two_runs(dir);
  // gnuplot records its pid and waits, as a slow one would, in the first diagram.
  const std::string path = fake_gnuplot(dir, "echo $$ > '" + (dir / "gnuplot.pid").string() +
                                                 "'\nexec sleep 120\n");
  const std::string command = "cd '" + dir.string() + "' && " + path + " exec '" CPS_EXE
                              "' report --merge runs --out out > /dev/null 2>&1";
  const pid_t cps = ::fork();
  REQUIRE(cps >= 0);
  if (cps == 0) {
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  pid_t gnuplot = 0;
  const bool started = wait_for(
      [&] {
        const std::string text = slurp(dir / "gnuplot.pid");
        if (text.empty() || text.back() != '\n') return false;
        gnuplot = std::stoi(text);
        return true;
      },
      std::chrono::seconds(60));
  ::kill(cps, SIGKILL);
  int status = 0;
  ::waitpid(cps, &status, 0);
  REQUIRE(started);
  CHECK(files_ending(dir / "out", ".tmp").size() == 3);  // the first diagram's pictures
  // gnuplot ends with cps (it would write the temporaries after the next run removed them).
  const bool gone = wait_for([&] { return ended(gnuplot); }, std::chrono::seconds(20));
  if (!gone) ::kill(gnuplot, SIGKILL);
  CHECK(gone);
  const Result r = run_cps("report --merge runs --out out", dir);
  INFO(r.err);
  CHECK(r.exit_code == 1);  // INCOMPLETE
  CHECK(files_ending(dir / "out", ".tmp").empty());
  CHECK(files_ending(dir / "out/plots", ".tmp").empty());
  CHECK(files_ending(dir / "out", ".pdf").size() == kStackPictures);
  fs::remove_all(dir);
}

TEST_CASE("report --merge refuses a run twice, naming the id and both files, and writes nothing",
          "[cli][report]") {
  const fs::path dir = fresh_dir("duplicates");
  two_runs(dir);
  SECTION("one folder twice") {
    for (const char* twice : {"runs runs", "runs ./runs/", "runs . "}) {
      INFO(twice);
      const Result r = run_cps(std::string("report --merge ") + twice + " --out out", dir);
      CHECK(r.exit_code == 2);
      CHECK(r.err.find("runs/stack.jacobi.split.fixed.it4.ss1.csv is below both") != std::string::npos);
      CHECK(r.err.find("give each folder once") != std::string::npos);
    }
  }
  SECTION("the same run in two files") {
    fs::create_directories(dir / "again");
    fs::copy_file(dir / "runs/stack.pgs.split.fixed.it4.ss1.csv", dir / "again/copy.csv");
    const Result r = run_cps("report --merge runs again --out out", dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("run stack.pgs.split.fixed.it4.ss1 is in runs/stack.pgs.split.fixed.it4.ss1.csv "
                     "line 2 and again in again/copy.csv line 2") != std::string::npos);
  }
  SECTION("an --out that is a merged folder or below one: its report would be read as runs") {
    const std::string before = slurp(dir / "runs/stack.pgs.split.fixed.it4.ss1.csv");
    for (const char* out : {"runs", "./runs/", "runs/report", "runs/../runs/x/y"}) {
      INFO(out);
      const Result r = run_cps(std::string("report --merge runs --out ") + out, dir);
      CHECK(r.exit_code == 2);
      CHECK(r.err.find("the --merge folder runs") != std::string::npos);
    }
    CHECK_FALSE(fs::exists(dir / "runs/report"));
    CHECK_FALSE(fs::exists(dir / "runs/report.md"));
    CHECK(slurp(dir / "runs/stack.pgs.split.fixed.it4.ss1.csv") == before);
  }
  SECTION("the same run twice in one file") {
    const std::string csv = slurp(dir / "runs/stack.pgs.split.fixed.it4.ss1.csv");
    fs::create_directories(dir / "twice");
    write_text(dir / "twice/a.csv", csv + "\n" + csv.substr(csv.find('\n') + 1));
    const Result r = run_cps("report --merge twice --out out", dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("is in twice/a.csv line 2 and again in twice/a.csv line 4") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}

TEST_CASE("report CSVs are RFC 4180: cells with commas, quotes and line breaks are quoted and read "
          "back, CRLF is read, an unclosed quote is named",
          "[cli][report]") {
  const fs::path dir = fresh_dir("rfc4180");
  cps::cli::CsvTable table;
  table.columns = {"scene", "note", "n"};
  table.rows = {{"a,b.json", "say \"hi\"", "1"}, {"two\nlines.json", "", "2"}, {"plain", "x", ""}};
  const std::string text = cps::cli::csv_text(table);
  CHECK(text == "scene,note,n\n\"a,b.json\",\"say \"\"hi\"\"\",1\n\"two\nlines.json\",,2\nplain,x,\n");
  write_text(dir / "lf.csv", text);
  std::string crlf;
  for (const char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  // The line break inside the quoted cell stays as written: CRLF outside quotes ends a record.
  write_text(dir / "crlf.csv", crlf);
  for (const char* name : {"lf.csv", "crlf.csv"}) {
    INFO(name);
    const cps::cli::CsvTable back = cps::cli::read_csv(dir / name);
    CHECK(back.columns == table.columns);
    REQUIRE(back.rows.size() == 3);
    CHECK(back.rows[0] == table.rows[0]);
    CHECK(back.rows[1][0].find("lines.json") != std::string::npos);
    CHECK(back.rows[2] == table.rows[2]);
    CHECK(back.lines == std::vector<std::size_t>{2, 3, 5});  // the second row spans lines 3 and 4
  }
  write_text(dir / "open.csv", "scene,n\nplain,1\n\"never closed,2\n");
  try {
    (void)cps::cli::read_csv(dir / "open.csv");
    FAIL("an unclosed quote was read");
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()).find("open.csv line 3: a quoted cell is not closed") != std::string::npos);
  }
  fs::remove_all(dir);
}

TEST_CASE("report --merge refuses two scenes with one output name, naming both, and writes nothing",
          "[cli][report]") {
  const fs::path dir = fresh_dir("one_name");
  two_runs(dir);
  // A scene file written from the stack keeps "name": "stack": its report files are the stack's.
  REQUIRE(run_cps("scene stack --out heavy.json", dir).exit_code == 0);
  REQUIRE(run_cps("report heavy.json --run heavy.json.pgs.split.fixed.it4.ss1 --out heavy", dir).exit_code == 0);
  const Result r = run_cps("report --merge runs heavy --out out", dir);
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("scenes stack and heavy.json are two scenes with one output name, stack") !=
        std::string::npos);
  CHECK_FALSE(fs::exists(dir / "out"));
  // Each alone merges.
  CHECK(run_cps("report --merge heavy --out out", dir).exit_code <= 1);
  CHECK(fs::exists(dir / "out/stack.csv"));
  fs::remove_all(dir);
}

TEST_CASE("report --merge refuses a cell that is not finite, naming file, line, column and value",
          "[cli][report]") {
  const fs::path dir = fresh_dir("non_finite");
  two_runs(dir);
  const std::string csv = slurp(dir / "runs/stack.pgs.split.fixed.it4.ss1.csv");
  const std::string header = csv.substr(0, csv.find('\n'));
  const std::string row = csv.substr(csv.find('\n') + 1);
  // Replaces the cell of `column` in the row.
  const auto with = [&](const std::string& column, const std::string& value) {
    std::vector<std::string> names, cells;
    std::stringstream h(header), r(row.substr(0, row.find('\n')));
    for (std::string c; std::getline(h, c, ',');) names.push_back(c);
    for (std::string c; std::getline(r, c, ',');) cells.push_back(c);
    std::string out;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      out += (i ? "," : "") + (names[i] == column ? value : cells[i]);
    }
    return header + "\n\n" + out + "\n";  // an empty line: the row is on line 3
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"trajectory_error_m", "nan"}, {"cpu_s_per_sim_s", "inf"}, {"metric.creep_m", "-inf"},
      {"residual_max_N", "1e999"},   {"warm_start", "NaN"},       {"solver", "nan"},
      {"penetration_max_m", "0.1x"}, {"diverged", "2"}};
  for (const auto& [column, value] : cases) {
    INFO(column << " = " << value);
    fs::remove_all(dir / "bad");
    fs::create_directories(dir / "bad");
    write_text(dir / "bad/a.csv", with(column, value));
    const Result r = run_cps("report --merge bad --out out", dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("bad/a.csv line 3, column " + column + ": '" + value + "'") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "out"));
  }
  fs::remove_all(dir);
}

TEST_CASE("report --merge bounds its memory by its cells, not by a count of rows or columns",
          "[cli][report]") {
  const fs::path dir = fresh_dir("too_much");
  fs::create_directories(dir / "wide");
  fs::create_directories(dir / "tall");
  fs::create_directories(dir / "fits");
  // 100 rows of 11,000 columns, and 1,100,000 rows of 1 column: each 1.1 million cells, past
  // the limit (256 MiB at 256 bytes per cell: 1,048,576 cells), however few rows or columns.
  std::string wide = "scene,solver,push,friction_model,iterations,substeps,diverged";
  for (int c = 0; c < 11000; ++c) wide += ",x" + std::to_string(c);
  wide += "\n";
  for (int i = 1; i <= 100; ++i) wide += "stack,pgs,baumgarte,fixed," + std::to_string(i) + ",1,0\n";
  write_text(dir / "wide/a.csv", wide);
  std::string tall = "scene\n";
  for (int i = 0; i < 1100000; ++i) tall += "x\n";
  write_text(dir / "tall/a.csv", tall);
  for (const char* folder : {"wide", "tall"}) {
    INFO(folder);
    const Result r = run_cps(std::string("report --merge ") + folder + " --out out", dir);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("cells") != std::string::npos);
    CHECK(r.err.find("the limit is 256 MiB") != std::string::npos);
    CHECK(r.err.find("would take at least 2") != std::string::npos);  // 25x or 26x MiB
    CHECK_FALSE(fs::exists(dir / "out"));
  }
  // A reference section's table (its header not starting with 'scene') of one 100 MB line: told
  // apart by its first bytes, never read to its end: the peak resident memory stays far below it.
  fs::create_directories(dir / "one_line");
  {
    std::ofstream big(dir / "one_line/stack_energy.csv", std::ios::binary);
    const std::string block(1 << 20, 'x');
    for (int k = 0; k < 100; ++k) big << block;
  }
  const auto [one_line, peak_mib] = run_cps_peak("report --merge one_line --out out", dir);
  INFO(one_line.err);
  CHECK(one_line.exit_code == 2);
  CHECK(one_line.err.find("no report CSV found") != std::string::npos);
  CHECK(peak_mib < 50);  // the line alone is 100 MiB
  fs::remove_all(dir / "one_line");
  // 100 rows of 1,000 columns: read (and refused for its settings, not its size).
  std::string fits = "scene,solver";
  for (int c = 0; c < 1000; ++c) fits += ",x" + std::to_string(c);
  fits += "\n";
  for (int i = 1; i <= 100; ++i) fits += "stack,pgs\n";
  write_text(dir / "fits/a.csv", fits);
  const Result r = run_cps("report --merge fits --out out", dir);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("a row without push") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("report --merge reads the studies' CSVs as strictly as the runs': a study given twice, "
          "an unknown study or a bad cell is refused, naming it, and nothing is written",
          "[cli][report]") {
  const fs::path dir = fresh_dir("study_input");
  // One run (the columns a run needs) beside each study table, so that the merge gets to them.
  const std::string run = "scene,solver,push,friction_model,iterations,substeps,diverged\n"
                          "stack,pgs,baumgarte,fixed,1,1,0\n";
  REQUIRE(run_cps("report --run mass_ratio.10.pgs.baumgarte --out study", dir).exit_code == 0);
  const std::string good = slurp(dir / "study/mass_ratio_10_pgs_baumgarte.csv");
  REQUIRE(good.rfind("study,", 0) == 0);
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from, text.find('\n'));
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
  };
  const auto cell_of = [&](std::size_t column) {  // the data row's cell
    std::istringstream row(good.substr(good.find('\n') + 1));
    std::string cell;
    for (std::size_t c = 0; c <= column; ++c) std::getline(row, cell, ',');
    return cell;
  };
  // Columns: study, solver, push, iterations, mass_ratio, seconds, held, heavy_height_m, ...
  const std::string held = cell_of(6);
  const std::string height = cell_of(7);
  struct Case {
    const char* name;
    std::vector<std::string> files;  // the study tables, each in a folder of its own
    std::vector<std::string> words;  // what the message names
  };
  const std::vector<Case> cases = {
      {"twice", {good, good}, {"mass_ratio.10.pgs.baumgarte", "merged once"}},
      {"unknown", {replaced("mass_ratio.10.pgs.baumgarte", "mass_ratio.7.pgs.baumgarte")},
       {"mass_ratio.7.pgs.baumgarte", "column study"}},
      {"held", {replaced("," + held + "," + height + ",", ",2," + height + ",")}, {"column held", "'2'"}},
      {"height", {replaced("," + height + ",", ",nan,")}, {"column heavy_height_m", "'nan'"}},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    std::string folders;
    for (std::size_t k = 0; k < c.files.size(); ++k) {
      const std::string folder = std::string(c.name) + "/" + std::to_string(k);
      fs::create_directories(dir / folder);
      write_text(dir / folder / "run.csv", run);
      write_text(dir / folder / "mass_ratio_10_pgs_baumgarte.csv", c.files[k]);
      folders += " " + folder;
      if (k > 0) fs::remove(dir / folder / "run.csv");  // the run once
    }
    const Result r = run_cps("report --merge" + folders + " --out out", dir);
    INFO(r.err);
    CHECK(r.exit_code == 2);
    for (const std::string& w : c.words) CHECK(r.err.find(w) != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "out"));
  }
  fs::remove_all(dir);
}
