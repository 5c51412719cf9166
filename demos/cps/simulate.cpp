#include "simulate.h"

#include "options.h"
#include "output.h"
#include "state_hash.h"

#include <chrono>
#include <fstream>
#include <string>
#include <system_error>

namespace cps::cli {
namespace {

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

TraceWriter::TraceWriter(std::filesystem::path path, bool force) : path_(std::move(path)) {
  std::error_code ec;
  if (!force && std::filesystem::exists(path_, ec)) {
    std::ifstream in(path_);
    std::string first;
    std::getline(in, first);
    if (first != kTraceHeader) {
      throw UsageError("--trace " + path_.string() +
                       " exists and is not a trace written by cps (its first line is not the "
                       "trace header); choose another file, or pass --force to replace it");
    }
  }
  tmp_ = path_;
  tmp_ += ".tmp";
  file_ = std::fopen(tmp_.c_str(), "w");
  if (file_ == nullptr) {
    throw std::runtime_error("--trace: cannot write " + tmp_.string() +
                             " (does the folder exist and is it writable?)");
  }
  std::fprintf(file_, "%s\n", std::string(kTraceHeader).c_str());
}

TraceWriter::~TraceWriter() {
  if (file_ != nullptr) {  // not finished: an error happened; leave no partial file behind
    std::fclose(file_);
    std::error_code ignored;
    std::filesystem::remove(tmp_, ignored);
  }
}

void TraceWriter::write(const World& world) {
  const long long step = static_cast<long long>(world.counters().steps);
  const double t = world.time();
  const auto& bodies = world.bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    const Vec3 v = b.velocity();
    const Vec3 w = b.angular_velocity();
    std::fprintf(file_,
                 "%lld,%.9g,%zu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                 step, t, i, b.x.x(), b.x.y(), b.x.z(), b.o.w(), b.o.x(), b.o.y(), b.o.z(), v.x(),
                 v.y(), v.z(), w.x(), w.y(), w.z());
    ++rows_;
  }
}

long TraceWriter::finish() {
  const bool ok = std::ferror(file_) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  std::error_code ec;
  if (!ok || !closed) {
    std::filesystem::remove(tmp_, ec);
    throw std::runtime_error("--trace: cannot write " + tmp_.string() + " (disk full?)");
  }
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp_, ignored);
    throw std::runtime_error("--trace: cannot rename " + tmp_.string() + " to " +
                             path_.string() + ": " + ec.message());
  }
  return rows_;
}

nlohmann::json simulate(const scenes::Scene& scene, scenes::Run& run, double seconds,
                        TraceWriter* trace) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  if (trace == nullptr) {
    run.advance_to(seconds);
  } else {
    trace->write(run.world);
    while (run.world.time() + 0.5 * run.world.def().dt < seconds) {  // as Run::advance_to
      run.step();
      trace->write(run.world);
    }
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();

  const StepCounters& c = run.world.counters();
  nlohmann::json bodies = nlohmann::json::array();
  for (const Body& b : run.world.bodies()) {
    if (b.is_static()) continue;
    bodies.push_back({{"position", vec(b.x)},
                      {"orientation", {b.o.w(), b.o.x(), b.o.y(), b.o.z()}},
                      {"velocity", vec(b.velocity())},
                      {"angular_velocity", vec(b.angular_velocity())}});
  }
  return {{"scene", scene.name},
          {"engine_version", engine_version()},
          {"parameters", parameters_json(run.world.def())},
          {"steps", c.steps},
          {"simulated_s", run.world.time()},
          {"wall_s", wall},
          {"us_per_step", c.steps > 0 ? 1e6 * wall / static_cast<double>(c.steps) : 0.0},
          {"metrics", run.metrics->report()},
          {"counters",
           {{"pairs_tested", c.pairs_tested},
            {"contacts", c.contacts},
            {"rows", c.rows},
            {"solves", c.solves}}},
          {"state_hash", scenes::format_hash(scenes::state_hash(run.world))},
          {"bodies", bodies}};
}

}  // namespace cps::cli
