#include "output/output.h"

#include "usage_error.h"

#include "cps_version.h"  // generated at build time by demos/cps/output/version.cmake

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace cps::cli {
namespace fs = std::filesystem;
namespace {

constexpr const char* k_tool = "cps";
constexpr std::size_t k_foreign_shown = 5;  // foreign entries named in a refusal message
constexpr std::size_t k_token_digits = 16;  // run_token()

// One run that began writing a folder: its token, how to tell whether it still runs, and the
// files it writes there.
struct RunId {
  std::string token;
  long long pid = 0;
  std::string host;
  long long start = 0;  // start time of the process (clock ticks after boot), 0 if unknown
  std::vector<std::string> files;
};

std::string host_name() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "unknown";
  return name;
}

// Start time of process `pid` (field 22 of /proc/PID/stat, clock ticks after boot), if known.
std::optional<long long> process_start(long long pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(in, line)) return std::nullopt;
  const std::size_t paren = line.rfind(')');  // the command name may hold spaces and ')'
  if (paren == std::string::npos) return std::nullopt;
  std::istringstream fields(line.substr(paren + 1));
  std::string field;
  for (int i = 3; i <= 22; ++i) {  // fields 3 (state) .. 22 (starttime)
    if (!(fields >> field)) return std::nullopt;
  }
  try {
    return std::stoll(field);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

RunId this_run() {
  RunId me;
  me.token = run_token();
  me.pid = ::getpid();
  me.host = host_name();
  me.start = process_start(me.pid).value_or(0);
  return me;
}

// False only when `run` surely ended: it ran on this host and its process is gone, or the pid
// now belongs to a process started at another time. A run on another host is taken as running.
bool still_running(const RunId& run) {
  if (run.host != host_name()) return true;
  if (run.pid <= 0) return false;
  if (run.pid == ::getpid()) return run.token == run_token();
  if (::kill(static_cast<pid_t>(run.pid), 0) != 0 && errno == ESRCH) return false;
  if (run.start > 0) {
    const std::optional<long long> start = process_start(run.pid);
    if (start && *start != run.start) return false;
  }
  return true;
}

nlohmann::json to_json(const RunId& r) {
  return {{"run_token", r.token}, {"pid", r.pid}, {"host", r.host}, {"start", r.start},
          {"files", r.files}};
}

bool plain_name(const std::string& name) {
  return !name.empty() && name.find('/') == std::string::npos && name != "." && name != "..";
}

// What run.json records of one file cps wrote ("" where it does not say: a manifest of an
// older cps, or a file of a run that did not end).
struct FileRecord {
  std::string command;  // the command that wrote it
  std::string scene;    // scene_source of the scene it shows
  std::string hash;     // XXH3-64 of its content, 16 hex digits
};
using Records = std::map<std::string, FileRecord>;

// What an output folder's run.json says, if it is cps's.
struct Manifest {
  bool present = false;               // an entry named run.json exists (of any kind)
  bool ours = false;                  // a regular file holding a cps manifest
  std::vector<std::string> files;     // listed, in order (plain names only)
  Records written;                    // records of listed files
  std::vector<RunId> unfinished;      // runs that began and did not end
};

// XXH3-64 of the file's content as 16 hex digits, or "" if it cannot be read.
std::string content_hash(const fs::path& p) {
  const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return {};
  XXH3_state_t* state = XXH3_createState();
  XXH3_64bits_reset(state);
  std::string buffer(1 << 16, '\0');
  bool ok = true;
  for (;;) {
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) ok = false;
    if (n <= 0) break;
    XXH3_64bits_update(state, buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(fd);
  const XXH64_hash_t h = XXH3_64bits_digest(state);
  XXH3_freeState(state);
  if (!ok) return {};
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

// The plain names (a manifest never reaches outside its folder) of a JSON array, run.json and
// duplicates left out.
std::vector<std::string> names_of(const nlohmann::json& list) {
  std::vector<std::string> names;
  if (!list.is_array()) return names;
  std::set<std::string> seen;
  for (const nlohmann::json& f : list) {
    if (!f.is_string()) continue;
    const std::string name = f.get<std::string>();
    if (plain_name(name) && name != k_manifest_name && seen.insert(name).second) names.push_back(name);
  }
  return names;
}

Manifest parse_manifest(const nlohmann::json& j) {
  Manifest m;
  if (!j.is_object() || j.value("tool", "") != k_tool || !j.contains("files") ||
      !j["files"].is_array()) {
    return m;
  }
  m.ours = true;
  m.files = names_of(j["files"]);
  if (j.contains("written") && j["written"].is_object()) {
    for (const std::string& name : m.files) {
      if (!j["written"].contains(name) || !j["written"][name].is_object()) continue;
      const nlohmann::json& r = j["written"][name];
      const auto text = [&r](const char* key) {
        return r.contains(key) && r[key].is_string() ? r[key].get<std::string>() : std::string();
      };
      m.written[name] = {text("command"), text("scene"), text("xxh3_64")};
    }
  }
  if (j.contains("unfinished_runs") && j["unfinished_runs"].is_array()) {
    for (const nlohmann::json& r : j["unfinished_runs"]) {
      if (!r.is_object() || !r.contains("run_token") || !r["run_token"].is_string()) continue;
      RunId id;
      id.token = r["run_token"].get<std::string>();
      if (id.token.size() != k_token_digits) continue;
      id.pid = r.value("pid", 0LL);
      id.host = r.value("host", std::string());
      id.start = r.value("start", 0LL);
      if (r.contains("files")) id.files = names_of(r["files"]);
      m.unfinished.push_back(id);
    }
  }
  return m;
}

std::optional<nlohmann::json> read_json(const fs::path& p) {
  struct stat st {};
  if (::lstat(p.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  std::ifstream in(p);
  if (!in) return std::nullopt;
  nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return std::nullopt;
  return j;
}

Manifest read_manifest(const fs::path& folder) {
  const fs::path p = folder / k_manifest_name;
  struct stat st {};
  const bool present = ::lstat(p.c_str(), &st) == 0;
  Manifest m;
  if (const std::optional<nlohmann::json> j = read_json(p)) m = parse_manifest(*j);
  m.present = present;
  return m;
}

// The temporaries in a folder that interrupted runs left, as its manifest identifies them.
class Leftovers {
 public:
  Leftovers(const fs::path& folder, const Manifest& m) : folder_(folder) {
    for (const RunId& r : m.unfinished) {
      if (still_running(r)) continue;
      ended_.insert(r.token);
      std::set<std::string>& names = dead_[r.token];
      names.insert(r.files.begin(), r.files.end());
      names.insert(k_manifest_name);
    }
  }

  // True if the unfinished run `token` had ended when this was made (a run ending later is
  // still taken as running, so that its temporaries stay recognised by the next run).
  bool ended(const std::string& token) const { return ended_.count(token) != 0; }

  // True if `name` is the temporary of one of the files (or run.json) of a run that ended
  // unfinished, or a temporary of run.json whose own content names such a run.
  bool contains(const std::string& name) const {
    const std::string suffix = ".tmp";
    if (name.size() < k_token_digits + 1 + suffix.size() + 1 || !name.ends_with(suffix)) return false;
    const std::size_t dot = name.size() - suffix.size() - k_token_digits - 1;
    if (name[dot] != '.') return false;
    const std::string base = name.substr(0, dot);
    const std::string token = name.substr(dot + 1, k_token_digits);
    if (temporary_name(base, token) != name) return false;
    const auto dead = dead_.find(token);
    if (dead != dead_.end() && dead->second.count(base) != 0) return true;
    if (base != k_manifest_name) return false;
    // run.json's temporary of a run killed while it wrote its first run.json.
    const std::optional<nlohmann::json> j = read_json(folder_ / name);
    if (!j) return false;
    for (const RunId& r : parse_manifest(*j).unfinished) {
      if (r.token == token) return !still_running(r);
    }
    return false;
  }

 private:
  fs::path folder_;
  std::map<std::string, std::set<std::string>> dead_;  // token -> names of its temporaries
  std::set<std::string> ended_;                         // tokens of the runs that ended
};

// An exclusive flock(2) on a folder while it lives; none where the file system refuses one.
class FolderLock {
 public:
  explicit FolderLock(const fs::path& folder) {
    fd_ = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd_ < 0) return;
    while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
    }
  }
  ~FolderLock() {
    if (fd_ >= 0) ::close(fd_);  // releases the lock
  }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

bool is_plain_file(const fs::path& p) {
  struct stat st {};
  return ::lstat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string display(const fs::path& folder) { return folder.empty() ? std::string(".") : folder.string(); }

// Throws UsageError unless `folder` is a folder this process may write into, or is missing and
// its nearest existing ancestor is one.
void check_folder(const fs::path& folder, std::string_view option) {
  const std::string choose = "; choose another " + std::string(option);
  fs::path p = folder.empty() ? fs::path(".") : folder;
  bool missing = false;
  for (;;) {
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0) {
      if (!S_ISDIR(st.st_mode)) {
        throw UsageError(missing ? "cannot create the output folder " + display(folder) + ": " +
                                       p.string() + " is a file, not a folder" + choose
                                 : "output folder " + display(folder) +
                                       " exists and is not a folder" + choose);
      }
      if (::access(p.c_str(), W_OK | X_OK) != 0) {
        throw UsageError("cannot write into " + p.string() + " (" +
                         (missing ? "to create " + display(folder) : std::string("the output folder")) +
                         "): " + std::strerror(errno) + choose);
      }
      return;
    }
    if (errno != ENOENT && errno != ENOTDIR) {
      throw UsageError("output folder " + display(folder) + ": " + p.string() + ": " +
                       std::strerror(errno) + choose);
    }
    struct stat link {};
    if (::lstat(p.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
      std::error_code ec;
      const fs::path to = fs::read_symlink(p, ec);
      throw UsageError("output folder " + display(folder) + ": " + p.string() +
                       " is a symbolic link to " + (ec ? std::string("a path") : to.string()) +
                       ", which does not exist (cps creates no folder through a dangling link); "
                       "create its target, or choose another " + std::string(option));
    }
    missing = true;
    fs::path parent = p.parent_path();
    if (parent.empty()) parent = ".";
    if (parent == p) return;  // the root itself is missing: let the creation report it
    p = parent;
  }
}

std::string joined(const std::vector<std::string>& names) {
  std::string shown;
  for (std::size_t i = 0; i < std::min(names.size(), k_foreign_shown); ++i) {
    shown += (i > 0 ? ", " : "") + names[i];
  }
  if (names.size() > k_foreign_shown) {
    shown += " and " + std::to_string(names.size() - k_foreign_shown) + " more";
  }
  return shown;
}

std::vector<std::string> present_files(const fs::path& folder, const std::vector<std::string>& names) {
  std::vector<std::string> out;
  for (const std::string& n : names) {
    if (is_plain_file(folder / n)) out.push_back(n);
  }
  return out;
}

// `a` followed by the names of `b` not in `a`.
std::vector<std::string> united(std::vector<std::string> a, const std::vector<std::string>& b) {
  std::set<std::string> seen(a.begin(), a.end());
  for (const std::string& n : b) {
    if (seen.insert(n).second) a.push_back(n);
  }
  return a;
}

// The names of `listed` that are files in `folder` or that one of `runs` is writing.
std::vector<std::string> still_listed(const fs::path& folder, const std::vector<std::string>& listed,
                                      const std::vector<RunId>& runs) {
  std::set<std::string> pending;
  for (const RunId& r : runs) pending.insert(r.files.begin(), r.files.end());
  std::vector<std::string> out;
  for (const std::string& n : listed) {
    if (pending.count(n) != 0 || is_plain_file(folder / n)) out.push_back(n);
  }
  return out;
}

void write_manifest(const fs::path& folder, const nlohmann::json& info, bool complete,
                    const std::vector<std::string>& files, const Records& records,
                    const std::vector<RunId>& unfinished) {
  nlohmann::json j = info;
  j["tool"] = k_tool;
  j["complete"] = complete;
  j["files"] = files;
  nlohmann::json written = nlohmann::json::object();
  for (const std::string& name : files) {
    const auto r = records.find(name);
    if (r == records.end()) continue;
    nlohmann::json entry = nlohmann::json::object();
    if (!r->second.command.empty()) entry["command"] = r->second.command;
    if (!r->second.scene.empty()) entry["scene"] = r->second.scene;
    if (!r->second.hash.empty()) entry["xxh3_64"] = r->second.hash;
    written[name] = entry;
  }
  j["written"] = written;
  nlohmann::json runs = nlohmann::json::array();
  for (const RunId& r : unfinished) runs.push_back(to_json(r));
  j["unfinished_runs"] = runs;
  write_json_atomic(folder / k_manifest_name, j);
}

// The inputs of this command (note_input).
struct Inputs {
  std::mutex mutex;
  std::vector<fs::path> paths;
};

Inputs& inputs() {
  static Inputs i;
  return i;
}

}  // namespace

void note_input(const fs::path& path) {
  Inputs& i = inputs();
  const std::lock_guard<std::mutex> lock(i.mutex);
  i.paths.push_back(path);
}

void clear_inputs() {
  Inputs& i = inputs();
  const std::lock_guard<std::mutex> lock(i.mutex);
  i.paths.clear();
}

namespace {

// Throws UsageError if `target` is one of this command's inputs (the same file by any path).
void check_not_input(const fs::path& target, std::string_view option) {
  Inputs& i = inputs();
  const std::lock_guard<std::mutex> lock(i.mutex);
  for (const fs::path& input : i.paths) {
    std::error_code ec;
    if (fs::equivalent(target, input, ec) && !ec) {
      throw UsageError(target.string() + " is an input of this command (" + input.string() +
                       "); cps never writes over its own input, even with --force; choose "
                       "another " + std::string(option));
    }
  }
}

// What plan_output found of the entries that are not cps's own (or not this command's to replace).
struct Findings {
  std::vector<std::string> foreign;   // not written by cps, or changed since
  std::vector<std::string> replaced;  // foreign files with a target's name
  std::vector<std::string> changed;   // listed, but their content is not what cps wrote
  std::vector<std::string> other_scene;  // targets an earlier run wrote for another scene, explained
};

std::string label_changed(const std::vector<std::string>& names,
                          const std::vector<std::string>& changed) {
  std::vector<std::string> shown;
  for (const std::string& n : names) {
    const bool edited = std::find(changed.begin(), changed.end(), n) != changed.end();
    shown.push_back(edited ? n + " (changed since cps wrote it)" : n);
  }
  return joined(shown);
}

[[noreturn]] void refuse_foreign(const OutputRequest& r, const Manifest& manifest,
                                 const Findings& f) {
  const std::string where = display(r.folder);
  const std::string record = (r.folder / k_manifest_name).string();
  const bool only_changed = f.changed.size() == f.foreign.size();
  const std::string why = !manifest.present ? "there is no cps run.json in " + where
                          : !manifest.ours  ? record + " is not cps's record of its files"
                          : only_changed    ? record + " records another content"
                                            : record + " does not list " +
                                                  (f.foreign.size() == 1 ? "it" : "them");
  if (r.use == FolderUse::exclusive) {
    throw UsageError(
        "output folder " + where + " holds " + std::to_string(f.foreign.size()) +
        " file(s) that no earlier cps run wrote there as they are (" +
        label_changed(f.foreign, f.changed) + ": " + why +
        "); nothing was written. Choose another " + r.option +
        ", or add --force to write into it anyway: --force keeps those files untouched" +
        (f.replaced.empty() ? std::string()
                            : ", except that a file with the name of one cps writes there (" +
                                  joined(f.replaced) + ") is replaced") +
        ".");
  }
  std::vector<std::string> paths;
  for (const std::string& n : f.foreign) paths.push_back((r.folder / n).string());
  const bool one = f.foreign.size() == 1;
  throw UsageError(label_changed(paths, [&] {
                     std::vector<std::string> c;
                     for (const std::string& n : f.changed) c.push_back((r.folder / n).string());
                     return c;
                   }()) +
                   (one ? " exists" : " exist") + " and no earlier cps run wrote " +
                   (one ? "it" : "them") + " there as " + (one ? "it is" : "they are") + " (" +
                   why + "); nothing was written. Choose another " + r.option +
                   ", or add --force to replace " + (one ? "it" : "them") +
                   " (--force replaces only files with the names cps writes; every other file "
                   "is kept untouched).");
}

// Sorts one existing entry `name` of the folder into the plan (stale, kept) or the findings.
// Throws UsageError for a target that is not a file or that another command wrote.
void classify(const OutputRequest& r, const Manifest& manifest, const Leftovers& leftovers,
              const std::set<std::string>& targets, const std::string& name, OutputPlan& plan,
              Findings& f) {
  const fs::path p = r.folder / name;
  struct stat st {};
  if (::lstat(p.c_str(), &st) != 0) return;  // gone meanwhile
  const bool regular = S_ISREG(st.st_mode);
  const bool target = targets.count(name) != 0;
  if (target && !regular && !S_ISLNK(st.st_mode)) {
    throw UsageError(p.string() + " exists and is not a file; cps writes a file of that name "
                     "there and replaces only files, even with --force; move it away, or "
                     "choose another " + r.option);
  }
  if (name == k_manifest_name) {
    if (!manifest.ours) {
      f.foreign.push_back(name);
      f.replaced.push_back(name);
    }
    return;
  }
  const bool listed =
      std::find(manifest.files.begin(), manifest.files.end(), name) != manifest.files.end();
  if (regular && manifest.ours && listed) {
    const auto found = manifest.written.find(name);
    const FileRecord record = found == manifest.written.end() ? FileRecord{} : found->second;
    if (record.hash.empty() || content_hash(p) == record.hash) {
      if (!record.command.empty() && record.command != r.command) {
        if (target) {
          throw UsageError(p.string() + " was written by cps " + record.command + "; cps " +
                           r.command + " writes a file of that name there and never replaces "
                           "another command's file, even with --force; choose another " + r.option);
        }
        if (r.use == FolderUse::exclusive) plan.kept.push_back(name);
        return;
      }
      const auto scene = r.scenes.find(name);
      if (target && scene != r.scenes.end() && !scene->second.empty() && !record.scene.empty() &&
          record.scene != scene->second) {
        if (!r.force) {
          f.other_scene.push_back(p.string() + " (an earlier cps run wrote it for " + record.scene +
                                  "; this run writes it for " + scene->second + ")");
        }
        return;
      }
      if (!target && r.use == FolderUse::exclusive) plan.stale.push_back(name);
      return;
    }
    f.changed.push_back(name);
  } else if (regular && leftovers.contains(name)) {
    return;
  }
  f.foreign.push_back(name);
  if (target) f.replaced.push_back(name);
}

}  // namespace

OutputPlan plan_output(const OutputRequest& r) {
  const fs::path& folder = r.folder;
  for (const std::string& name : r.files) {
    if (!plain_name(name) || name == k_manifest_name) {
      throw UsageError("cannot write a file named '" + name + "' in " + display(folder) +
                       (name == k_manifest_name ? " (run.json is cps's record of that folder)" : "") +
                       "; choose another " + r.option);
    }
  }
  OutputPlan plan;
  plan.folder = folder;
  plan.use = r.use;
  plan.command = r.command;
  plan.files = r.files;
  plan.scenes = r.scenes;
  check_folder(folder, r.option);
  std::error_code ec;
  if (!fs::is_directory(folder.empty() ? fs::path(".") : folder, ec)) return plan;  // created later

  std::set<std::string> targets(plan.files.begin(), plan.files.end());
  targets.insert(k_manifest_name);
  for (const std::string& t : targets) check_not_input(folder / t, r.option);
  const Manifest manifest = read_manifest(folder);

  if (r.use == FolderUse::exclusive && !r.force) {
    for (const RunId& run : manifest.unfinished) {
      if (still_running(run) && run.token != run_token()) {
        throw UsageError("another cps run (pid " + std::to_string(run.pid) + " on " + run.host +
                         ") is writing into " + display(folder) +
                         "; wait for it to end, or choose another " + r.option +
                         " (or add --force if that run has ended: its files are then kept)");
      }
    }
  }
  // Each existing target (and, for an exclusive folder, each other entry) is the earlier runs'
  // own, their leftover, another command's, or foreign.
  std::vector<std::string> names;
  if (r.use == FolderUse::exclusive) {
    for (const fs::directory_entry& e : fs::directory_iterator(folder.empty() ? fs::path(".") : folder)) {
      names.push_back(e.path().filename().string());
    }
  } else {
    for (const std::string& t : targets) {
      struct stat st {};
      if (::lstat((folder / t).c_str(), &st) == 0) names.push_back(t);
    }
  }
  std::sort(names.begin(), names.end());
  const Leftovers leftovers(folder, manifest);
  Findings findings;
  for (const std::string& name : names) {
    classify(r, manifest, leftovers, targets, name, plan, findings);
  }
  if (!findings.other_scene.empty()) {
    const std::string them = findings.other_scene.size() == 1 ? "it" : "them";
    throw UsageError(joined(findings.other_scene) + ": two scenes with one name; nothing was "
                     "written. Rename one (its file, or its \"name\"), choose another " + r.option +
                     ", or add --force to replace " + them + ".");
  }
  if (r.force || findings.foreign.empty()) return plan;
  refuse_foreign(r, manifest, findings);
}

namespace {

// The folders this process began (begin_output) and has not ended, with the info of their
// run.json, for abandon_outputs.
struct Begun {
  fs::path folder;
  nlohmann::json info;
};
std::mutex begun_mutex;
std::vector<Begun> begun;

void note_begun(const fs::path& folder, const nlohmann::json& info) {
  const std::lock_guard lock(begun_mutex);
  begun.push_back({folder, info});
}

void note_ended(const fs::path& folder) {
  const std::lock_guard lock(begun_mutex);
  const auto it = std::find_if(begun.begin(), begun.end(), [&](const Begun& b) { return b.folder == folder; });
  if (it != begun.end()) begun.erase(it);
}

}  // namespace

void abandon_outputs() noexcept {
  std::vector<Begun> folders;
  {
    const std::lock_guard lock(begun_mutex);
    folders.swap(begun);
  }
  for (const Begun& b : folders) {
    try {
      const FolderLock lock(b.folder);
      const Manifest manifest = read_manifest(b.folder);
      if (!manifest.ours) continue;
      std::vector<RunId> unfinished;
      for (const RunId& r : manifest.unfinished) {
        if (r.token != run_token()) unfinished.push_back(r);
      }
      const std::vector<std::string> files = still_listed(b.folder, manifest.files, unfinished);
      if (files.empty() && unfinished.empty()) {
        // Nothing of cps's is there: a manifest would list nothing.
        ::unlink((b.folder / k_manifest_name).c_str());
        continue;
      }
      write_manifest(b.folder, b.info, unfinished.empty(), files, manifest.written, unfinished);
    } catch (...) {  // best effort: the next run there treats this one as interrupted
    }
  }
}

void begin_output(const OutputPlan& plan, const nlohmann::json& info) {
  const fs::path folder = plan.folder.empty() ? fs::path(".") : plan.folder;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) {
    throw std::runtime_error("cannot create the output folder " + folder.string() + ": " +
                             ec.message());
  }
  const FolderLock lock(folder);
  const Manifest manifest = read_manifest(folder);
  const Leftovers leftovers(folder, manifest);
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (!is_plain_file(e.path()) || !leftovers.contains(name)) continue;
    if (::unlink(e.path().c_str()) != 0 && errno != ENOENT) {
      throw std::runtime_error("cannot remove " + e.path().string() +
                               " (a temporary file of an interrupted cps run): " +
                               std::strerror(errno));
    }
  }
  std::vector<RunId> unfinished;
  for (const RunId& r : manifest.unfinished) {
    // The same verdict as the removal's: a run that ends meanwhile stays listed, else its
    // temporaries would never be removed.
    if (r.token != run_token() && !leftovers.ended(r.token)) unfinished.push_back(r);
  }
  RunId me = this_run();
  me.files = plan.files;
  unfinished.push_back(me);
  std::vector<std::string> files = plan.files;
  if (plan.use == FolderUse::exclusive) {
    files = united(files, present_files(folder, united(plan.stale, plan.kept)));
  } else if (manifest.ours) {
    files = united(still_listed(folder, manifest.files, unfinished), files);
  }
  Records records = manifest.written;
  for (const std::string& name : plan.files) {
    const auto scene = plan.scenes.find(name);
    records[name] = {plan.command, scene == plan.scenes.end() ? std::string() : scene->second, ""};
  }
  write_manifest(folder, info, false, files, records, unfinished);
  note_begun(folder, info);
}

void end_output(const OutputPlan& plan, const nlohmann::json& info) {
  const fs::path folder = plan.folder.empty() ? fs::path(".") : plan.folder;
  const FolderLock lock(folder);
  if (plan.use == FolderUse::exclusive) {
    for (const std::string& name : plan.stale) {
      if (::unlink((folder / name).c_str()) != 0 && errno != ENOENT) {
        throw std::runtime_error("cannot remove " + (folder / name).string() +
                                 " (a file of an earlier cps run): " + std::strerror(errno));
      }
    }
  }
  const Manifest manifest = read_manifest(folder);
  std::vector<RunId> unfinished;
  for (const RunId& r : manifest.unfinished) {
    if (r.token != run_token()) unfinished.push_back(r);
  }
  const std::vector<std::string> written = present_files(folder, plan.files);
  std::vector<std::string> files = written;
  if (plan.use == FolderUse::exclusive) {
    files = united(files, present_files(folder, plan.kept));
  } else if (manifest.ours) {
    files = united(still_listed(folder, manifest.files, unfinished), files);
  }
  Records records = manifest.written;
  for (const std::string& name : written) {
    const auto scene = plan.scenes.find(name);
    records[name] = {plan.command, scene == plan.scenes.end() ? std::string() : scene->second,
                     content_hash(folder / name)};
  }
  write_manifest(folder, info, unfinished.empty(), files, records, unfinished);
  note_ended(folder);
}

void write_json_atomic(const fs::path& path, const nlohmann::json& j) {
  write_text_atomic(path, j.dump(2) + "\n");
}

nlohmann::json run_info(const std::string& command, int argc, char** argv,
                        const nlohmann::json& parameters) {
  nlohmann::json line = nlohmann::json::array();
  for (int i = 0; i < argc; ++i) line.push_back(argv[i]);
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return {{"command", command},
          {"command_line", line},
          {"engine_version", engine_version()},
          {"date_utc", date},
          {"parameters", parameters}};
}

nlohmann::json parameter_json(const Parameter& p, const ParameterValue& v) {
  switch (p.type) {
    case ParameterType::choice:
      return p.format(v);
    case ParameterType::vector3: {
      const Vec3& x = std::get<Vec3>(v);
      return {x.x(), x.y(), x.z()};
    }
    case ParameterType::real:
      return std::holds_alternative<int>(v) ? static_cast<double>(std::get<int>(v)) : std::get<double>(v);
    case ParameterType::integer:
      return std::get<int>(v);
    case ParameterType::boolean:
      return std::get<bool>(v);
  }
  return nullptr;
}

nlohmann::json overrides_json(const scenes::Overrides& o) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [p, value] : o.values) j[std::string(p->json_key)] = parameter_json(*p, value);
  return j;
}

nlohmann::json parameters_json(const WorldDef& def) {
  nlohmann::json j = nlohmann::json::object();
  for (const Parameter& p : world_parameters()) j[std::string(p.json_key)] = parameter_json(p, p.get(def));
  return j;
}

std::string scene_source(std::string_view scene_name) {
  const std::string name(scene_name);
  if (!name.ends_with(".json")) return "scene " + name;
  std::error_code ec;
  fs::path path = fs::weakly_canonical(fs::absolute(name, ec), ec);
  if (ec) path = fs::absolute(name, ec);
  return "file " + path.string();
}

const char* engine_version() { return CPS_ENGINE_VERSION; }

}  // namespace cps::cli
