#include "tempera/engine/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace tempera {

namespace {
std::atomic<int> g_thread_start_limit{-1};  // testing: threads that may start, < 0 unlimited

std::thread start_thread(const std::function<void()>& fn) {
  if (g_thread_start_limit.load() == 0)
    throw std::system_error(std::make_error_code(std::errc::resource_unavailable_try_again), "thread start");
  if (g_thread_start_limit.load() > 0) --g_thread_start_limit;
  return std::thread(fn);
}
}  // namespace

int hardware_threads() { return int(std::max(1u, std::thread::hardware_concurrency())); }

int resolve_threads(int requested) {
  const int cores = hardware_threads();
  return requested > 0 ? std::min(requested, cores) : cores;
}

void set_thread_start_limit_for_testing(int limit) { g_thread_start_limit = limit; }

void parallel_for(int count, int threads, const std::function<void(int)>& fn) {
  threads = std::min(resolve_threads(threads), count);
  if (threads <= 1) {
    for (int i = 0; i < count; ++i) fn(i);
    return;
  }
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    for (int i = next++; i < count; i = next++) {
      try {
        fn(i);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        next = count;  // stop handing out work
      }
    }
  };
  std::vector<std::thread> pool;
  // A thread that cannot start (ulimit -u, memory) is no error: the started
  // ones and this thread share all the work, as items are handed out, not split.
  try {
    for (int t = 1; t < threads; ++t) pool.push_back(start_thread(worker));
  } catch (const std::system_error&) {
  }
  worker();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace tempera
