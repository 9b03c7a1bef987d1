#include "eval/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace jg::eval {

int default_jobs() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0U ? 1 : static_cast<int>(n);
}

void parallel_for(std::size_t count, int jobs, const std::function<void(std::size_t)>& body,
                  const std::function<void(double)>& progress) {
  if (count == 0) return;
  const auto threads = static_cast<std::size_t>(std::clamp<long long>(jobs, 1, static_cast<long long>(count)));
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex failure_mutex;
  std::size_t failed_index = count;
  std::exception_ptr failure;
  std::atomic<bool> stop{false};
  auto work = [&](bool report) {
    for (std::size_t i = next++; i < count && !stop.load(); i = next++) {
      try {
        body(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (i < failed_index) {
          failed_index = i;
          failure = std::current_exception();
        }
        stop = true;
      }
      ++done;
      if (report && progress) progress(static_cast<double>(done.load()) / static_cast<double>(count));
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work, false);
  work(true);
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  if (progress) progress(1.0);
}

}  // namespace jg::eval
