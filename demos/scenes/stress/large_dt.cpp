// stack_dt_0.1 and pendulum_wave_dt_0.1: two of the paper's scenes at a time step six times
// (the stack) and sixty times (the wave) their own. Nothing must blow up: the energy may only
// fall, apart from what the push factor puts in.
#include "stress/stress.h"

namespace cps::scenes {
namespace {

constexpr double kLargeDt = 0.1;  // s

// The energy keys of EnergyMetrics, with the largest rise E(t) - E(0) named energy_growth_J.
class LargeDtMetrics final : public EnergyMetrics {
 public:
  nlohmann::json report() const override {
    nlohmann::json j = EnergyMetrics::report();
    j["energy_growth_J"] = j["max_energy_gain_J"];
    j.erase("max_energy_gain_J");
    return j;
  }
};

}  // namespace

WorldDef stack_dt_01_world_def() {
  WorldDef def = stack_world_def();
  def.dt = kLargeDt;
  return def;
}

WorldDef pendulum_wave_dt_01_world_def() {
  WorldDef def = pendulum_wave_world_def();
  def.dt = kLargeDt;
  return def;
}

std::unique_ptr<Metrics> make_large_dt_metrics(const World& world) {
  return observed<LargeDtMetrics>(world);
}

}  // namespace cps::scenes
