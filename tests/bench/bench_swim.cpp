// Swim kernel costs per frame (no Python, no Blender): the body axis with length
// keeping (fixed-point passes + curve-length passes) and a fin axis. Both run once
// per frame per fish, so they should stay in the microseconds whatever the mesh size.
#include <benchmark/benchmark.h>

#include "kodawari/swim/body_wave.hpp"
#include "kodawari/swim/fin_motion.hpp"

using namespace kodawari;
using namespace kodawari::swim;

static void BM_body_axis(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Vec3List rest;
  for (int i = 0; i < n; ++i) rest.emplace_back(Real(i) / (n - 1), 0, 0);
  BodyWave wave;
  wave.wavelength = 0.6;
  wave.amplitude = 0.08;
  wave.amplitude_head = 0.04;
  wave.preserve_length = state.range(1) != 0;
  Real phase = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(body_axis(rest, Vec3(0, 1, 0), 1.0, wave, phase));
    phase += 0.1;
  }
}
BENCHMARK(BM_body_axis)->Args({8, 0})->Args({8, 1})->Args({16, 1})->Args({32, 1})->Unit(benchmark::kMicrosecond);

static void BM_fin_axis(benchmark::State& state) {
  const Vec3List rest{{0, 0, 0}, {0, 0.02, 0}, {0, 0.04, 0}, {0, 0.5, 0}, {0, 1, 0}};
  FinWave wave;
  wave.feathering = 1.0;
  Real phase = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(fin_axis(rest, RootFrame{}, wave, phase));
    phase += 0.1;
  }
}
BENCHMARK(BM_fin_axis)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
