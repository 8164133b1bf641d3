#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "kodawari/parallel.hpp"

using kodawari::parallel_for_dynamic;

TEST(ParallelForDynamic, VisitsEveryIndexExactlyOnceInChunksOfTheGrain) {
  for (std::size_t count : {0u, 1u, 7u, 16u, 17u, 1000u, 100003u}) {
    for (unsigned threads : {1u, 2u, 3u, 8u}) {
      std::vector<std::atomic<int>> visits(count);
      std::atomic<bool> oversized{false};
      parallel_for_dynamic(count, threads, 16, [&](std::size_t begin, std::size_t end) {
        if (threads > 1 && end - begin > 16) oversized = true;
        for (std::size_t i = begin; i < end; ++i) visits[i].fetch_add(1);
      });
      for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(visits[i].load(), 1) << "count " << count << " threads " << threads;
      EXPECT_FALSE(oversized.load()) << "count " << count << " threads " << threads;
    }
  }
}

TEST(ParallelForDynamic, AStalledThreadDoesNotKeepItsShare) {
  // The chunk that starts at 0 sleeps; the other thread must take every other chunk.
  std::vector<std::thread::id> owner(64);
  parallel_for_dynamic(64, 2, 8, [&](std::size_t begin, std::size_t end) {
    if (begin == 0) std::this_thread::sleep_for(std::chrono::milliseconds(200));
    for (std::size_t i = begin; i < end; ++i) owner[i] = std::this_thread::get_id();
  });
  std::size_t with_first = 0;
  for (const auto& id : owner) with_first += id == owner[0];
  EXPECT_EQ(with_first, 8u);
}
