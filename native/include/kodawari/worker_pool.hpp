// Parallel chunks on threads kept for the life of the process, for work done every frame.
//
// parallel_for / parallel_for_dynamic (parallel.hpp) start threads per call and join them:
// on a busy machine a new thread may wait milliseconds for a core, and the caller waits for
// it even when it has done every chunk itself meanwhile (measured: a 100 k-vertex deform took
// 0.69 ms on two threads against 0.35 ms on one, machine load 4.5 on 2 cores). Here the
// caller takes chunks like any worker and returns as soon as every chunk is done; a worker
// that wakes late finds none left. Each index is computed by exactly one thread with the
// same arithmetic, so results never depend on the thread count.
#pragma once

#include <cstddef>
#include <functional>

namespace kodawari {

// Calls body(begin, end) on disjoint chunks of at most `grain` indices covering [0, count),
// on up to `threads` threads (0 = as many as the hardware has) counting the caller. `body`
// must not throw. A call made while another is running (another thread, or from inside a
// body) runs on its caller alone.
void parallel_chunks(std::size_t count, unsigned threads, std::size_t grain,
                     const std::function<void(std::size_t, std::size_t)>& body);

}  // namespace kodawari
