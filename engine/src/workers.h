#pragma once
// Threads that run one task together, in the single-program style of Box2D v3's solver stages
// (erincatto/box2d src/solver.c, b2SolverStep): every thread runs the same task with its own
// index and they meet at barriers between the stages. Between tasks the workers spin a while
// before they sleep, as Box2D v3's and enkiTS's workers do: a step runs a dozen short tasks
// with a little serial work between them, and waking a sleeping thread costs tens of
// microseconds on a virtual machine. The spins are timed by the clock, not counted in pauses: a
// pause takes from a few to over a hundred cycles by the processor (Box2D v3's solver notes the
// same). A waiting thread does not yield the core while it spins: beside a busy process a yield
// hands the core to that process for its time slice, not to the thread waited for
// (docs/benchmarks.md). With more threads than the processor runs at once, none spins: a spinning
// thread would hold a core that the thread it waits for needs.

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <vector>

namespace cps {

/// `count` threads (>= 1; less is taken as 1): the calling thread and count - 1 kept workers,
/// which sleep between tasks (after spinning kIdleSpin; at once when count exceeds
/// std::thread::hardware_concurrency()). Not copyable. Errors: the constructor throws
/// std::system_error when a thread cannot be started (or std::bad_alloc), after joining those
/// it started.
class Workers {
 public:
  explicit Workers(int count);
  ~Workers();
  Workers(const Workers&) = delete;
  Workers& operator=(const Workers&) = delete;

  /// Threads, counting the caller.
  int count() const { return count_; }

  /// Runs task(t) for t in [0, count()) at once, t = 0 on the calling thread, and returns when
  /// every one has returned. The task must not throw, and must call sync() the same number of
  /// times on every thread.
  template <class Task>
  void run(Task& task) {
    ++tasks_;  // published to the workers by start()
    if (count_ == 1) {
      task(0);
      return;
    }
    call_ = [](void* f, int t) { (*static_cast<Task*>(f))(t); };
    task_ = &task;
    start();
    task(0);
    finish();
  }

  /// Most blocks a thread in a stage that BlockClaims hands out (count).
  static constexpr std::size_t kBlocksPerThread = 8;
  /// Most blocks a stage BlockClaims hands out may have: kBlocksPerThread times count().
  std::size_t max_blocks() const { return block_stamps_.size(); }

  /// Waits until every thread of the running task has reached this call (a barrier); nothing
  /// with one thread. It spins for up to kSpin before it sleeps: a sweep meets a barrier after
  /// each graph colour, some microseconds apart, while waking a sleeping thread takes tens of
  /// microseconds on a virtual machine.
  void sync();

 private:
  void start();
  void finish();
  void loop(int t);
  void stop_and_join();

  /// How long a waiting thread spins before it sleeps, at a barrier and while the caller waits
  /// for a task's end (typically 50 us: longer than the threads' arrivals differ once the blocks
  /// even out; a longer spin holds a core that a preempted thread of the task needs while other
  /// processes run).
  static constexpr std::chrono::microseconds kSpin{50};
  /// How long an idle worker spins before it sleeps, waiting for the next task (typically 1 ms:
  /// longer than the serial work between a step's tasks, a caller's per-step bookkeeping of 0.5
  /// to 0.8 ms included; a worker that sleeps there wakes late for the next task).
  static constexpr std::chrono::microseconds kIdleSpin{1000};

  // Spins for up to `spin` while value == old, then sleeps until it changes.
  template <class T>
  static void wait_while(const std::atomic<T>& value, T old, std::chrono::microseconds spin);

  int count_ = 1;
  // kSpin and kIdleSpin, or 0 when there are more threads than the processor runs at once: a
  // thread that spins then holds a core the thread it waits for may need (set once).
  std::chrono::microseconds spin_ = kSpin;
  std::chrono::microseconds idle_spin_ = kIdleSpin;
  std::atomic<int> arrived_{0};               // threads at the current barrier
  std::atomic<std::uint32_t> phase_{0};       // barriers passed
  std::atomic<std::uint32_t> generation_{0};  // tasks started (and the stop)
  std::atomic<int> running_{0};               // workers still in the current task
  std::atomic<bool> stop_{false};
  // BlockClaims' claims: per block, the stamp of the last stage that claimed it (each on a line
  // of its own: the threads write them), and the tasks run so far.
  struct alignas(64) BlockStamp {
    std::atomic<std::uint64_t> stamp{0};
  };
  std::vector<BlockStamp> block_stamps_;
  std::uint64_t tasks_ = 0;
  friend class BlockClaims;
  void (*call_)(void*, int) = nullptr;
  void* task_ = nullptr;
  std::vector<std::thread> threads_;
};

/// Runs fn(t, begin, end) for each thread t of `workers` on its share [begin, end) of the items
/// [0, count), split evenly in order (the same shares for a given thread count), and returns when
/// all have returned; with no workers, one thread, or fewer than `min_parallel` items (count;
/// below it waking the threads costs more than the work), fn(0, 0, count) on the calling thread.
/// For work whose items write only their own results, so the result is the same for every thread
/// count. fn must not throw.
template <class Fn>
void parallel_for(Workers* workers, std::size_t count, std::size_t min_parallel, Fn&& fn) {
  if (workers == nullptr || workers->count() == 1 || count < min_parallel) {
    fn(0, std::size_t{0}, count);
    return;
  }
  const auto threads = static_cast<std::size_t>(workers->count());
  auto share = [&](int t) {
    const auto k = static_cast<std::size_t>(t);
    fn(t, count * k / threads, count * (k + 1) / threads);
  };
  workers->run(share);
}

/// Thread t's claims on the blocks of the stages of a task that `workers` runs, as Box2D v3's
/// solver hands out a stage's blocks (erincatto/box2d src/solver.c, b2ExecuteMainStage): each
/// thread first claims the blocks of its own even share, in order, then any block still
/// unclaimed, from the last one down. On even cores each thread sweeps the same share in every
/// stage (its caches hold it); a thread on a slower core (a busy neighbour on a virtual machine)
/// leaves the end of its share to the others instead of holding them at the barrier. For stages
/// whose blocks write only their own results (one graph colour), so the result is the same for
/// every thread count and schedule. Every thread of the task makes one BlockClaims at the
/// task's start and, for every such stage in the same order, calls stage() and then next() until
/// it returns false; the stages are separated by Workers::sync(). No errors.
class BlockClaims {
 public:
  BlockClaims(Workers& workers, int t)
      : stamps_(workers.block_stamps_.data()),
        threads_(static_cast<std::size_t>(workers.count())),
        t_(static_cast<std::size_t>(t)),
        stamp_(workers.tasks_ << 32) {}

  /// Begins a stage of `blocks` blocks (count in [1, Workers::max_blocks()], the same on every
  /// thread).
  void stage(std::size_t blocks) {
    ++stamp_;
    next_ = blocks * t_ / threads_;
    own_end_ = blocks * (t_ + 1) / threads_;
    steal_ = blocks;
  }

  /// The next block this thread claims in the stage, into `block`; false when none is left.
  bool next(std::size_t& block) {
    while (next_ < own_end_) {
      if (claim(next_)) {
        block = next_++;
        return true;
      }
      ++next_;
    }
    while (steal_ > 0) {
      --steal_;
      if (claim(steal_)) {
        block = steal_;
        return true;
      }
    }
    return false;
  }

 private:
  bool claim(std::size_t k) {
    std::atomic<std::uint64_t>& s = stamps_[k].stamp;
    std::uint64_t seen = s.load(std::memory_order_relaxed);
    while (seen < stamp_) {
      if (s.compare_exchange_weak(seen, stamp_, std::memory_order_relaxed)) return true;
    }
    return false;
  }

  Workers::BlockStamp* stamps_;
  std::size_t threads_;
  std::size_t t_;
  std::uint64_t stamp_;  // the task in the high half, its stage in the low
  std::size_t next_ = 0;
  std::size_t own_end_ = 0;
  std::size_t steal_ = 0;
};

/// Runs fn(begin, end) over blocks that cover the items [0, count) in order, on the threads of
/// `workers`, each thread claiming blocks as BlockClaims hands them out: first those of its own
/// even share, then any still unclaimed, from the last one down. A thread that is done early then
/// takes over the end of a slower thread's share instead of waiting for it at the task's end.
/// With no workers, one thread, or fewer than `min_parallel` items (count), fn(0, count) on the
/// calling thread. For work whose items write only their own results, so the result is the same
/// for every thread count and schedule. fn must not throw.
template <class Fn>
void parallel_blocks(Workers* workers, std::size_t count, std::size_t min_parallel, Fn&& fn) {
  if (workers == nullptr || workers->count() == 1 || count < min_parallel) {
    fn(std::size_t{0}, count);
    return;
  }
  const std::size_t blocks = count < workers->max_blocks() ? count : workers->max_blocks();
  auto task = [&](int t) {
    BlockClaims claims(*workers, t);
    claims.stage(blocks);
    for (std::size_t block; claims.next(block);) fn(count * block / blocks, count * (block + 1) / blocks);
  };
  workers->run(task);
}

/// Runs fn(k) for every chunk k in [0, chunks) on the threads of `workers`, each thread taking
/// the next chunk no thread has taken yet (so uneven chunks even out); with no workers or one
/// thread, in order on the calling thread. For chunks that write only their own results, so the
/// result is the same for every thread count and schedule. fn must not throw.
template <class Fn>
void parallel_chunks(Workers* workers, std::size_t chunks, Fn&& fn) {
  if (workers == nullptr || workers->count() == 1 || chunks <= 1) {
    for (std::size_t k = 0; k < chunks; ++k) fn(k);
    return;
  }
  std::atomic<std::size_t> next{0};
  auto take = [&](int) {
    for (std::size_t k = next.fetch_add(1, std::memory_order_relaxed); k < chunks;
         k = next.fetch_add(1, std::memory_order_relaxed)) {
      fn(k);
    }
  };
  workers->run(take);
}

inline Workers::Workers(int count) : count_(count < 1 ? 1 : count) {
  const unsigned cores = std::thread::hardware_concurrency();  // 0: unknown
  if (cores != 0 && static_cast<unsigned>(count_) > cores) spin_ = idle_spin_ = std::chrono::microseconds{0};
  try {
    block_stamps_ = std::vector<BlockStamp>(kBlocksPerThread * static_cast<std::size_t>(count_));
    threads_.reserve(static_cast<std::size_t>(count_ - 1));
    for (int t = 1; t < count_; ++t) threads_.emplace_back([this, t] { loop(t); });
  } catch (...) {
    stop_and_join();  // the threads already started, before the members go
    throw;
  }
}

inline Workers::~Workers() { stop_and_join(); }

template <class T>
inline void Workers::wait_while(const std::atomic<T>& value, T old, std::chrono::microseconds spin) {
  if (value.load(std::memory_order_acquire) != old) return;
  if (spin.count() > 0) {
    // The clock is read every 64 pauses (a microsecond or more), at tens of nanoseconds a read.
    using Clock = std::chrono::steady_clock;
    const Clock::time_point until = Clock::now() + spin;
    do {
      for (int i = 0; i < 64; ++i) {
        if (value.load(std::memory_order_acquire) != old) return;
#if defined(__x86_64__) || defined(__i386__)
        __builtin_ia32_pause();
#endif
      }
    } while (Clock::now() < until);
  }
  while (value.load(std::memory_order_acquire) == old) value.wait(old, std::memory_order_acquire);
}

inline void Workers::sync() {
  if (count_ == 1) return;
  // The phase cannot move on before this thread arrives, so this is the barrier's own phase.
  const std::uint32_t phase = phase_.load(std::memory_order_acquire);
  if (arrived_.fetch_add(1, std::memory_order_acq_rel) == count_ - 1) {  // the last one
    arrived_.store(0, std::memory_order_relaxed);
    phase_.store(phase + 1, std::memory_order_release);
    phase_.notify_all();
    return;
  }
  wait_while(phase_, phase, spin_);
}

inline void Workers::stop_and_join() {
  stop_.store(true, std::memory_order_release);
  generation_.fetch_add(1, std::memory_order_acq_rel);
  generation_.notify_all();
  for (std::thread& thread : threads_) thread.join();
  threads_.clear();
}

inline void Workers::start() {
  // The task and the count are written before the generation moves on (release), so a worker
  // that sees the new generation sees them.
  running_.store(count_ - 1, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_acq_rel);
  generation_.notify_all();
}

inline void Workers::finish() {
  for (int left = running_.load(std::memory_order_acquire); left != 0;
       left = running_.load(std::memory_order_acquire)) {
    wait_while(running_, left, spin_);
  }
}

inline void Workers::loop(int t) {
  std::uint32_t seen = 0;
  for (;;) {
    wait_while(generation_, seen, idle_spin_);
    seen = generation_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_acquire)) return;
    call_(task_, t);
    if (running_.fetch_sub(1, std::memory_order_acq_rel) == 1) running_.notify_all();
  }
}

}  // namespace cps
