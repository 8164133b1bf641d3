#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "kodawari/worker_pool.hpp"

using kodawari::parallel_chunks;

TEST(WorkerPool, VisitsEveryIndexExactlyOnceInChunksOfTheGrain) {
  for (std::size_t count : {0u, 1u, 7u, 16u, 17u, 1000u, 100003u}) {
    for (unsigned threads : {0u, 1u, 2u, 3u, 8u}) {
      std::vector<std::atomic<int>> visits(count);
      std::atomic<bool> oversized{false};
      parallel_chunks(count, threads, 16, [&](std::size_t begin, std::size_t end) {
        if (end - begin > 16) oversized = true;
        for (std::size_t i = begin; i < end; ++i) visits[i].fetch_add(1);
      });
      for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(visits[i].load(), 1) << "count " << count << " threads " << threads;
      EXPECT_FALSE(oversized.load()) << "count " << count << " threads " << threads;
    }
  }
}

TEST(WorkerPool, TheCallerDoesNotWaitForAWorkerThatHasNothingLeft) {
  // Many calls in a row, each returning only when all its chunks are done: a late worker
  // of one call must never run a chunk of a call that has already returned.
  for (int call = 0; call < 2000; ++call) {
    std::vector<int> visits(64, 0);
    parallel_chunks(64, 0, 8, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) ++visits[i];
    });
    for (int v : visits) ASSERT_EQ(v, 1) << "call " << call;
  }
}

TEST(WorkerPool, CallsFromSeveralThreadsAndFromInsideABodyAllComplete) {
  std::atomic<long> total{0};
  auto run = [&] {
    for (int call = 0; call < 200; ++call) {
      parallel_chunks(1000, 0, 100, [&](std::size_t begin, std::size_t end) {
        // nested: runs on its caller alone
        parallel_chunks(end - begin, 0, 10, [&](std::size_t b, std::size_t e) { total += long(e - b); });
      });
    }
  };
  std::thread other(run);
  run();
  other.join();
  EXPECT_EQ(total.load(), 2L * 200 * 1000);
}

TEST(WorkerPool, AStalledChunkDoesNotKeepTheOthers) {
  std::vector<std::thread::id> owner(64);
  parallel_chunks(64, 2, 8, [&](std::size_t begin, std::size_t end) {
    if (begin == 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    for (std::size_t i = begin; i < end; ++i) owner[i] = std::this_thread::get_id();
  });
  std::size_t with_first = 0;
  for (const auto& id : owner) with_first += id == owner[0];
  if (std::thread::hardware_concurrency() > 1) EXPECT_EQ(with_first, 8u);
}
