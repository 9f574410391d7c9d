#pragma once
// Deterministic parallel loops: work is split into fixed items whose results
// never depend on which thread ran them or in which order, so output depends
// only on the seed (not even on the thread count).
#include <functional>

namespace tempera {

// Number of worker threads to use: `requested` if > 0, else all cores.
int resolve_threads(int requested);

// Calls fn(item) for item in [0, count) on `threads` threads. Exceptions from
// any item are rethrown on the calling thread after all workers stop.
void parallel_for(int count, int threads, const std::function<void(int)>& fn);

}  // namespace tempera
