#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <vector>

#include "kodawari/parallel.hpp"

using kodawari::parallel_for;

TEST(ParallelFor, VisitsEveryIndexExactlyOnce) {
  for (std::size_t count : {0u, 1u, 7u, 1000u, 100003u}) {
    for (unsigned threads : {1u, 2u, 3u, 8u}) {
      std::vector<std::atomic<int>> visits(count);
      parallel_for(count, threads, 16, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) visits[i].fetch_add(1);
      });
      for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(visits[i].load(), 1) << "count " << count << " threads " << threads;
    }
  }
}

TEST(ParallelFor, ResultsDoNotDependOnThreadCount) {
  const std::size_t count = 50000;
  auto run = [&](unsigned threads) {
    std::vector<double> out(count);
    parallel_for(count, threads, 64, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) out[i] = std::sin(0.001 * double(i)) * std::exp(-1e-5 * double(i));
    });
    return out;
  };
  const auto one = run(1);
  EXPECT_EQ(one, run(2));
  EXPECT_EQ(one, run(5));
}
