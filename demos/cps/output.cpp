#include "output.h"

#include "options.h"

#include "cps_version.h"  // generated at build time by demos/cps/version.cmake

#include <algorithm>
#include <ctime>
#include <fstream>
#include <set>
#include <stdexcept>
#include <system_error>

namespace cps::cli {
namespace fs = std::filesystem;
namespace {

constexpr const char* k_tool = "cps";
constexpr std::size_t k_foreign_shown = 5;  // foreign entries named in the refusal message

// The files an earlier cps run listed in `folder`/run.json, or nothing (no manifest, or not
// one of ours: then run.json itself is foreign and `ours` is false).
std::set<std::string> own_files(const fs::path& folder, bool& ours) {
  ours = false;
  std::set<std::string> files;
  std::ifstream in(folder / k_manifest_name);
  if (!in) return files;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || j.value("tool", "") != k_tool || !j.contains("files") ||
      !j["files"].is_array()) {
    return files;
  }
  for (const nlohmann::json& f : j["files"]) {
    if (!f.is_string()) continue;
    const std::string name = f.get<std::string>();
    // Only plain names: a manifest never reaches outside its folder.
    if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..") continue;
    files.insert(name);
  }
  ours = true;
  return files;
}

void write_manifest(const OutputPlan& plan, const nlohmann::json& info, bool complete,
                    const std::vector<std::string>& files) {
  nlohmann::json j = info;
  j["tool"] = k_tool;
  j["complete"] = complete;
  j["files"] = files;
  write_json_atomic(plan.folder / k_manifest_name, j);
}

}  // namespace

OutputPlan plan_output(const fs::path& folder, std::vector<std::string> files, bool force) {
  OutputPlan plan;
  plan.folder = folder;
  plan.files = std::move(files);
  std::error_code ec;
  const fs::file_status status = fs::status(folder, ec);
  if (!fs::exists(status)) return plan;
  if (!fs::is_directory(status)) {
    throw UsageError("output folder " + folder.string() +
                     " exists and is not a folder; choose another --out");
  }
  bool ours = false;
  const std::set<std::string> own = own_files(folder, ours);
  const std::set<std::string> writes(plan.files.begin(), plan.files.end());
  std::vector<std::string> foreign;
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    const bool plain = e.is_regular_file() && !e.is_symlink();
    if (plain && name == k_manifest_name && ours) continue;
    if (plain && own.count(name) != 0) {
      if (writes.count(name) == 0) plan.stale.push_back(name);
      continue;
    }
    if (plain && name.size() > 4 && name.ends_with(".tmp") &&
        (own.count(name.substr(0, name.size() - 4)) != 0 ||
         (ours && name == std::string(k_manifest_name) + ".tmp"))) {
      plan.leftovers.push_back(name);
      continue;
    }
    foreign.push_back(name);
  }
  std::sort(plan.stale.begin(), plan.stale.end());
  std::sort(plan.leftovers.begin(), plan.leftovers.end());
  if (!foreign.empty() && !force) {
    std::sort(foreign.begin(), foreign.end());
    std::string shown;
    for (std::size_t i = 0; i < std::min(foreign.size(), k_foreign_shown); ++i) {
      shown += (i > 0 ? ", " : "") + foreign[i];
    }
    if (foreign.size() > k_foreign_shown) {
      shown += " and " + std::to_string(foreign.size() - k_foreign_shown) + " more";
    }
    throw UsageError("output folder " + folder.string() + " holds " +
                     std::to_string(foreign.size()) +
                     " file(s) that no earlier cps run wrote there (" + shown +
                     "); nothing was written. Choose another --out, or add --force to write "
                     "into it anyway (those files are kept; files with the names of new frames "
                     "are replaced).");
  }
  return plan;
}

void begin_output(const OutputPlan& plan, const nlohmann::json& info) {
  std::error_code ec;
  fs::create_directories(plan.folder, ec);
  if (ec) {
    throw std::runtime_error("cannot create the output folder " + plan.folder.string() + ": " +
                             ec.message());
  }
  std::vector<std::string> listed = plan.files;
  listed.insert(listed.end(), plan.stale.begin(), plan.stale.end());
  write_manifest(plan, info, false, listed);
}

void end_output(const OutputPlan& plan, const nlohmann::json& info) {
  for (const std::vector<std::string>* names : {&plan.stale, &plan.leftovers}) {
    for (const std::string& name : *names) {
      std::error_code ec;
      fs::remove(plan.folder / name, ec);
      if (ec) {
        throw std::runtime_error("cannot remove " + (plan.folder / name).string() +
                                 " (a file of an earlier run): " + ec.message());
      }
    }
  }
  write_manifest(plan, info, true, plan.files);
}

void write_json_atomic(const fs::path& path, const nlohmann::json& j) {
  fs::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << j.dump(2) << "\n";
    out.flush();
    if (!out) {
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw std::runtime_error("cannot write " + tmp.string());
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw std::runtime_error("cannot rename " + tmp.string() + " to " + path.string() + ": " +
                             ec.message());
  }
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

const char* engine_version() { return CPS_ENGINE_VERSION; }

}  // namespace cps::cli
