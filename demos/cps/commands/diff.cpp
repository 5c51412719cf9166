// `cps diff A B`: two PNG files, or two frame folders, compared frame by frame with a tolerance
// (pictures/image_diff.h); a diff picture for each frame past it; exit 0 within, 1 past, 2 for
// bad input, 3 for any other failure.
#include "command.h"
#include "options/options.h"
#include "output/output.h"
#include "pictures/image_diff.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace cps::cli {
namespace {

namespace fs = std::filesystem;

/// A channel differs when |a - b| exceeds this (levels of 255). Typical 8: llvmpipe's output
/// moves by a few levels between CPUs and Mesa versions (docs/commands.md, `diff`).
constexpr double kDefaultThresholdLevels = 8.0;
/// A frame passes while at most this percentage of its pixels differ. Typical 0.1 %.
constexpr double kDefaultTolerancePercent = 0.1;

/// The exit code of `cps diff` for a failure that is neither a usage error (2) nor frames that
/// differ (1): a diff picture that cannot be written, memory exhausted.
constexpr int kDiffErrorExit = 3;

struct DiffOptions {
  std::string a;
  std::string b;
  double threshold = kDefaultThresholdLevels;  // levels
  double tolerance = kDefaultTolerancePercent; // % of a frame's pixels
  std::string out = "out/diff";
  bool force = false;
};

// One pair of frames: its name and the two paths (either missing when a folder lacks it).
struct FramePair {
  std::string name;
  std::optional<fs::path> a;
  std::optional<fs::path> b;
};

std::vector<std::string> png_names(const fs::path& folder) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    if (e.path().extension() != ".png") continue;
    std::error_code status_ec;
    const bool regular = e.is_regular_file(status_ec);
    if (status_ec) throw UsageError(e.path().string() + ": cannot be read: " + status_ec.message());
    if (regular) names.push_back(e.path().filename().string());
    if (static_cast<double>(names.size()) > kMaxFrames) {
      throw UsageError(folder.string() + ": more than " +
                       std::to_string(static_cast<long long>(kMaxFrames)) +
                       " PNG files; cps diff compares at most that many frames");
    }
  }
  if (ec) throw UsageError(folder.string() + ": cannot be read: " + ec.message());
  std::sort(names.begin(), names.end());
  return names;
}

// True for a folder, false for a regular file (links followed). Throws UsageError for a missing
// path, a link loop or another unreadable status, and for anything else (a FIFO, a device), which
// cps diff never opens: reading it could block for ever.
bool is_folder_to_compare(const fs::path& p) {
  std::error_code ec;
  const fs::file_status status = fs::status(p, ec);
  if (status.type() == fs::file_type::not_found) {
    throw UsageError(p.string() + ": no such file or folder (give two PNG files or two frame "
                     "folders)");
  }
  if (ec) throw UsageError(p.string() + ": cannot be read: " + ec.message());
  if (fs::is_directory(status)) return true;
  if (fs::is_regular_file(status)) return false;
  throw UsageError(p.string() + ": neither a regular file nor a folder (cps diff compares PNG "
                   "files or frame folders)");
}

// Refuses an --out that is one of the compared folders, or the folder of a compared file: the
// diff pictures would become frames of the next comparison there.
void refuse_out_among_inputs(const DiffOptions& o, bool folders) {
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(fs::path(o.out), ec);
  if (ec) return;  // plan_output reports an --out it cannot use
  for (const std::string& input : {o.a, o.b}) {
    const fs::path in = folders ? fs::path(input) : fs::path(input).parent_path();
    const fs::path folder = fs::weakly_canonical(in.empty() ? fs::path(".") : in, ec);
    if (!ec && folder == out) {
      throw UsageError("--out " + o.out + " is " + (folders ? "the compared folder " : "the folder of ") +
                       input + ": give another folder for the diff pictures, so they never become "
                       "frames of the next comparison");
    }
  }
}

// The frames to compare: one pair for two files, the union of the PNG names for two folders.
// Throws UsageError for a missing path, a file beside a folder, or folders without PNG files.
std::vector<FramePair> frame_pairs(const DiffOptions& o) {
  const fs::path a(o.a);
  const fs::path b(o.b);
  const bool a_dir = is_folder_to_compare(a);
  const bool b_dir = is_folder_to_compare(b);
  if (a_dir != b_dir) {
    throw UsageError((a_dir ? a : b).string() + " is a folder and " + (a_dir ? b : a).string() +
                     " is not: give two PNG files or two frame folders");
  }
  refuse_out_among_inputs(o, a_dir);
  if (!a_dir) return {{a.filename().string(), a, b}};
  const std::vector<std::string> in_a = png_names(a);
  const std::vector<std::string> in_b = png_names(b);
  if (in_a.empty() && in_b.empty()) {
    throw UsageError(a.string() + " and " + b.string() + " hold no PNG files (give two frame "
                     "folders of cps render, or two PNG files)");
  }
  std::set<std::string> all(in_a.begin(), in_a.end());
  all.insert(in_b.begin(), in_b.end());
  std::vector<FramePair> pairs;
  for (const std::string& n : all) {
    FramePair p{n, std::nullopt, std::nullopt};
    if (std::binary_search(in_a.begin(), in_a.end(), n)) p.a = a / n;
    if (std::binary_search(in_b.begin(), in_b.end(), n)) p.b = b / n;
    pairs.push_back(p);
  }
  return pairs;
}

render::Image read_or_usage_error(const fs::path& p) {
  try {
    return render::read_png(p);
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string(e.what()) + " (cps diff compares PNG files)");
  }
}

std::string diff_name(const std::string& frame) {
  return fs::path(frame).stem().string() + "-diff.png";
}

int run_diff(const DiffOptions& o, int argc, char** argv) {
  // --out is checked before any work, though it is written only for frames past the tolerance.
  plan_output({.folder = fs::path(o.out), .files = {}, .command = "diff", .use = FolderUse::shared,
               .scenes = {}, .force = o.force});
  const std::vector<FramePair> pairs = frame_pairs(o);
  std::vector<std::string> failed;   // frames past the tolerance, both present and of one size
  long long within = 0;
  long long missing = 0;
  for (const FramePair& p : pairs) {
    if (!p.a || !p.b) {
      std::printf("%s: only in %s\n", p.name.c_str(), (p.a ? o.a : o.b).c_str());
      ++missing;
      continue;
    }
    note_input(*p.a);
    note_input(*p.b);
    const render::Image ia = read_or_usage_error(*p.a);
    const render::Image ib = read_or_usage_error(*p.b);
    const ImageDiff d = compare_images(ia, ib, o.threshold);
    if (!d.same_size) {
      std::printf("%s: sizes differ (%dx%d and %dx%d)\n", p.name.c_str(), ia.width, ia.height,
                  ib.width, ib.height);
      ++missing;
      continue;
    }
    const bool ok = d.past_percent() <= o.tolerance;
    std::printf("%s: max %d levels, mean %.4f, %lld pixels past %g levels (%.4f %%): %s\n",
                p.name.c_str(), d.max_abs, d.mean_abs, d.past, o.threshold, d.past_percent(),
                ok ? "within" : "PAST the tolerance");
    if (ok) {
      ++within;
    } else {
      failed.push_back(p.name);
    }
  }
  const std::string rule = "at most " + shortest_decimal(o.tolerance) + " % of a frame's pixels past " +
                           shortest_decimal(o.threshold) + " levels";
  if (!failed.empty()) {
    std::vector<std::string> files;
    for (const std::string& f : failed) files.push_back(diff_name(f));
    const OutputPlan plan = plan_output({.folder = fs::path(o.out),
                                         .files = files,
                                         .command = "diff",
                                         .use = FolderUse::shared,
                                         .scenes = {},
                                         .force = o.force});
    const nlohmann::json info = run_info("diff", argc, argv,
                                         {{"reference", o.a}, {"frames", o.b}, {"threshold_levels", o.threshold},
                                          {"tolerance_percent", o.tolerance}});
    begin_output(plan, info);
    for (const FramePair& p : pairs) {
      if (std::find(failed.begin(), failed.end(), p.name) == failed.end()) continue;
      const render::Image picture =
          diff_picture(render::read_png(*p.a), render::read_png(*p.b), o.threshold);
      write_file_atomic(fs::path(o.out) / diff_name(p.name), render::encode_png(picture));
    }
    end_output(plan, info);
  }
  const long long total = static_cast<long long>(pairs.size());
  if (failed.empty() && missing == 0) {
    std::printf("cps diff: %lld of %lld frames within the tolerance (%s)\n", within, total, rule.c_str());
    return 0;
  }
  std::printf("cps diff: %zu of %lld frames past the tolerance (%s), %lld unmatched (missing or of "
              "another size)%s\n",
              failed.size(), total, rule.c_str(), missing,
              failed.empty() ? "" : ("; the diff pictures are in " + o.out).c_str());
  return 1;
}

}  // namespace

Command add_diff(CLI::App& app, int argc, char** argv) {
  auto o = std::make_shared<DiffOptions>();
  CLI::App* sub = app.add_subcommand(
      "diff", "compare two PNG files or two frame folders with a tolerance: exit 0 within, 1 past");
  sub->add_option("reference", o->a, "the baseline: a PNG file, or a frame folder")
      ->required()
      ->check(kNotEmpty);
  sub->add_option("frames", o->b, "the PNG file or frame folder compared with it")
      ->required()
      ->check(kNotEmpty);
  sub->add_option("--threshold", o->threshold,
                  "a channel differs when |a - b| exceeds this many levels of 255, in [0, 255]")
      ->transform(decimal_in(0.0, 255.0, false, "levels"))
      ->default_str(shortest_decimal(kDefaultThresholdLevels));
  sub->add_option("--tolerance", o->tolerance,
                  "a frame passes while at most this percentage of its pixels differ, in [0, 100]")
      ->transform(decimal_in(0.0, 100.0, false, "%"))
      ->default_str(shortest_decimal(kDefaultTolerancePercent));
  sub->add_option("--out", o->out,
                  "folder for the diff pictures of the frames past the tolerance (FRAME-diff.png: "
                  "the differing pixels in red)")
      ->check(kNotEmpty)
      ->default_str("out/diff");
  sub->add_flag("--force", o->force,
                "replace diff pictures that no cps run wrote (the output rule, docs/commands.md)");
  // Exit 1 means "frames differ" alone: any other failure (a file that cannot be written, memory)
  // exits 3 with its message; usage errors exit 2 in main.
  return {sub, [o, argc, argv] {
            try {
              return run_diff(*o, argc, argv);
            } catch (const UsageError&) {
              throw;
            } catch (const std::exception& e) {
              abandon_outputs();
              std::fprintf(stderr, "cps: error: %s\n", e.what());
              return kDiffErrorExit;
            }
          }};
}

}  // namespace cps::cli
