#pragma once
// Deterministic parallel loops: work is split into fixed items whose results
// never depend on which thread ran them or in which order, so output depends
// only on the seed (not even on the thread count).
#include <functional>

namespace tempera {

// Number of worker threads to use: `requested` if > 0 but at most the cores
// (more would only cost memory and may fail to start), else all cores.
int resolve_threads(int requested);
int hardware_threads();

// Testing only: after `limit` more thread starts, starting a thread fails as
// it does under `ulimit -u` (< 0: no limit, the default).
void set_thread_start_limit_for_testing(int limit);

// Calls fn(item) for item in [0, count) on `threads` threads. Exceptions from
// any item are rethrown on the calling thread after all workers stop. If a
// worker thread cannot be started, the ones started and the calling thread
// do all the items (same results: they never depend on the thread count).
void parallel_for(int count, int threads, const std::function<void(int)>& fn);

}  // namespace tempera
