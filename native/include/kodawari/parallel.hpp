// Splits an index range over threads. Each index is computed by exactly one
// thread with the same arithmetic, so results never depend on the thread count.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace kodawari {

// 0 means "as many as the hardware has".
inline unsigned resolve_thread_count(unsigned requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? hw : 1;
}

// Calls body(begin, end) on disjoint chunks of [0, count). Ranges smaller than
// min_chunk per thread stay on the calling thread: spawning costs ~20 us.
template <typename Body>
void parallel_for(std::size_t count, unsigned threads, std::size_t min_chunk, Body&& body) {
  const std::size_t workers = std::min<std::size_t>(
      resolve_thread_count(threads), std::max<std::size_t>(1, count / std::max<std::size_t>(1, min_chunk)));
  if (workers <= 1) {
    body(std::size_t(0), count);
    return;
  }
  const std::size_t chunk = (count + workers - 1) / workers;
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  for (std::size_t w = 1; w < workers; ++w) {
    const std::size_t begin = w * chunk;
    const std::size_t end = std::min(count, begin + chunk);
    if (begin >= end) break;
    pool.emplace_back([&body, begin, end] { body(begin, end); });
  }
  body(std::size_t(0), std::min(count, chunk));
  for (auto& t : pool) t.join();
}

// Like parallel_for, but threads take chunks of `grain` indices from a shared counter
// until none are left: on a busy machine a thread that is descheduled does not hold
// up the others with a fixed half of the work. Each index is still computed by exactly
// one thread with the same arithmetic, so results never depend on the thread count.
template <typename Body>
void parallel_for_dynamic(std::size_t count, unsigned threads, std::size_t grain, Body&& body) {
  grain = std::max<std::size_t>(1, grain);
  const std::size_t chunks = (count + grain - 1) / grain;
  const std::size_t workers = std::min<std::size_t>(resolve_thread_count(threads), chunks);
  if (workers <= 1) {
    body(std::size_t(0), count);
    return;
  }
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t c = next.fetch_add(1); c < chunks; c = next.fetch_add(1)) {
      body(c * grain, std::min(count, (c + 1) * grain));
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

}  // namespace kodawari
