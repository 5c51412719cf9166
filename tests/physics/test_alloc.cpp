// The step allocates nothing once its buffers have reached their working size: after a few
// simulated seconds of warm-up, N more steps of every paper scene make no heap allocation (a hard
// bound, counted, not a timing). This is its own executable: the global operator new below
// counts every allocation of the process and must not replace the allocator of the other tests.
#include "scene.h"

#include <catch2/catch.hpp>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

namespace {

std::atomic<long> g_allocations{0};

void* counted_allocation(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}

void* counted_aligned_allocation(std::size_t size, std::align_val_t alignment) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const auto a = static_cast<std::size_t>(alignment);
  const std::size_t rounded = (size + a - 1) / a * a;  // aligned_alloc wants a multiple
  if (void* p = std::aligned_alloc(a, rounded == 0 ? a : rounded)) return p;
  throw std::bad_alloc();
}

long allocations() { return g_allocations.load(std::memory_order_relaxed); }

}  // namespace

void* operator new(std::size_t size) { return counted_allocation(size); }
void* operator new[](std::size_t size) { return counted_allocation(size); }
void* operator new(std::size_t size, std::align_val_t a) { return counted_aligned_allocation(size, a); }
void* operator new[](std::size_t size, std::align_val_t a) { return counted_aligned_allocation(size, a); }
// The nothrow forms too: a library calling them would otherwise get the default allocator's
// memory and free it with the free() below (AddressSanitizer reports the mismatch).
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_allocation(size);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t& t) noexcept { return operator new(size, t); }
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return counted_aligned_allocation(size, a);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t& t) noexcept {
  return operator new(size, a, t);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

using namespace cps;

namespace {

constexpr double kWarmUp = 3.0;  // s of simulated time before counting
constexpr int kCountedSteps = 3000;  // 50 s at 60 Hz

// Allocations made by `steps` steps of the world (only World::step is counted, not metrics).
long allocations_in_steps(World& world, int steps) {
  const long before = allocations();
  for (int k = 0; k < steps; ++k) world.step();
  return allocations() - before;
}

}  // namespace

TEST_CASE("the allocation counter sees an allocation", "[alloc]") {
  const long before = allocations();
  auto* v = new std::vector<double>(100, 1.0);  // two allocations: the vector and its storage
  const long counted = allocations() - before;
  delete v;
  CHECK(counted >= 2);
}

TEST_CASE("after warm-up a step of every paper scene allocates nothing", "[alloc]") {
  struct Variant {
    const char* name;
    SolverKind solver;
    PushMode push;
    double warm_start;  // the cache and the initial guesses keep their storage too
    int threads = 1;
    RowPrecision precision = RowPrecision::double_precision;
  };
  for (const scenes::Scene& scene : scenes::paper_scenes()) {
    for (const Variant& v : {Variant{"pgs baumgarte", SolverKind::pgs, PushMode::baumgarte, 0.0},
                             Variant{"pgs split", SolverKind::pgs, PushMode::split, 0.0},
                             Variant{"jacobi baumgarte", SolverKind::jacobi, PushMode::baumgarte, 0.0},
                             Variant{"pgs baumgarte warm 0.8", SolverKind::pgs, PushMode::baumgarte, 0.8},
                             Variant{"pgs split warm 1", SolverKind::pgs, PushMode::split, 1.0},
                             Variant{"jacobi split warm 0.8", SolverKind::jacobi, PushMode::split, 0.8},
                             Variant{"pgs split-impulse", SolverKind::pgs, PushMode::split_impulse, 0.0},
                             Variant{"pgs soft warm 0.8", SolverKind::pgs, PushMode::soft, 0.8},
                             Variant{"jacobi soft", SolverKind::jacobi, PushMode::soft, 0.0},
                             Variant{"pgs ngs", SolverKind::pgs, PushMode::ngs, 0.0},
                             Variant{"coloured-pgs baumgarte, 2 threads", SolverKind::coloured_pgs,
                                     PushMode::baumgarte, 0.0, 2},
                             Variant{"pgs split warm 1, float rows", SolverKind::pgs, PushMode::split, 1.0, 1,
                                     RowPrecision::single_precision}}) {
      scenes::Overrides o;
      o.set("solver", v.solver);
      o.set("push", v.push);
      o.set("warm_start", v.warm_start);
      o.set("assembly", Assembly::matrix_free);
      o.set("threads", v.threads);
      o.set("row_precision", v.precision);
      scenes::Run run = scenes::make_run(scene, o);
      // Under the soft step the pendulum grid's shapes settle later: its rows grow from at most
      // 142 in the first 3 s to 169 by 11 s, past the headroom of the step's own buffers (World's
      // rows), so it warms up until they have.
      // Coloured PGS sweeps in another order: its grid reaches its largest row count at 6.5 s,
      // and its stack's contacts come and go for longer (new largest counts up to 84 rows at
      // 47 s, where PGS has its 72 by 1.7 s).
      const bool coloured = v.solver == SolverKind::coloured_pgs;
      double warm_up = kWarmUp;
      if ((v.push == PushMode::soft && scene.name == "pendulum_grid") || coloured) warm_up = 12.0;
      if (coloured && scene.name == "stack") warm_up = 60.0;
      while (run.world.time() < warm_up) run.world.step();
      const long counted = allocations_in_steps(run.world, kCountedSteps);
      INFO(std::string(scene.name) << ", " << v.name << ": " << counted << " allocations in "
                                   << kCountedSteps << " steps after " << warm_up << " s");
      CHECK(counted == 0);
    }
  }
}

TEST_CASE("after warm-up a step with the residual measured allocates nothing", "[alloc]") {
  scenes::Overrides o;
  o.set("measure_residual", true);
  scenes::Run run = scenes::make_run(*scenes::find_scene("funnel"), o);
  while (run.world.time() < kWarmUp) run.world.step();
  CHECK(allocations_in_steps(run.world, kCountedSteps) == 0);
}
