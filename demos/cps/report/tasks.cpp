#include "report/tasks.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>

namespace cps::cli {

int default_jobs() {
  const unsigned n = std::thread::hardware_concurrency();
  return std::clamp(static_cast<int>(n), 1, kMaxJobs);
}

void run_tasks(const std::vector<std::function<void()>>& tasks, int jobs,
               const std::function<void(std::size_t)>& done) {
  std::vector<std::exception_ptr> errors(tasks.size());
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex done_mutex;
  const auto work = [&] {
    for (std::size_t i; !failed && (i = next++) < tasks.size();) {
      try {
        tasks[i]();
      } catch (...) {
        errors[i] = std::current_exception();
        failed = true;
        continue;
      }
      const std::lock_guard<std::mutex> lock(done_mutex);
      if (done) done(i);
    }
  };
  const std::size_t threads = std::min<std::size_t>(static_cast<std::size_t>(std::max(jobs, 1)), tasks.size());
  if (threads <= 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
  }
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace cps::cli
