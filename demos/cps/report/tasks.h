#pragma once
// The report's work spread over threads: independent tasks run by a fixed number of workers,
// and values computed once per key however many tasks ask for them.

#include <cstddef>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace cps::cli {

/// The threads `cps report` computes with by default (count): the machine's logical CPUs
/// (std::thread::hardware_concurrency), at least 1, at most kMaxJobs.
int default_jobs();

/// The most threads `cps report --jobs` accepts (count).
inline constexpr int kMaxJobs = 256;

/// Runs each of `tasks` once on min(jobs, tasks) threads (jobs >= 1; with 1, in order on the
/// calling thread). Tasks must not depend on each other's order; each writes only its own
/// results. `done(i)` is called after task i ends, under a lock (one call at a time). If a task
/// throws, no task not yet begun is begun, and once every thread has stopped the exception of
/// the lowest-numbered task that threw is rethrown.
void run_tasks(const std::vector<std::function<void()>>& tasks, int jobs,
               const std::function<void(std::size_t)>& done);

/// A value per key, made by the first caller of get() for that key and kept for the process:
/// callers of the same key meanwhile wait for it, callers of other keys do not. Thread-safe. If
/// `make` throws, the exception reaches that caller and the next caller of the key makes it again.
template <class Value>
class OnceCache {
 public:
  template <class Make>
  const Value& get(const std::string& key, Make&& make) {
    Entry* e = nullptr;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      e = &entries_[key];  // map nodes never move
    }
    std::call_once(e->once, [&] { e->value = make(); });
    return e->value;
  }

 private:
  struct Entry {
    std::once_flag once;
    Value value{};
  };
  std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

}  // namespace cps::cli
