// Native FFD costs without Python or Blender: deform per vertex from 10k to 4M
// vertices (should be flat per vertex), the per-call frame table, and bind.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "kodawari/ffd/control_axis.hpp"

using namespace kodawari;
using namespace kodawari::ffd;

namespace {

Vec3List axis(Real phase) {
  Vec3List points;
  for (int i = 0; i < 8; ++i) {
    const Real s = i / 7.0;
    points.emplace_back(4 * s, 0.6 * s * s * std::sin(2 * kPi * s - phase), 0);
  }
  return points;
}

std::vector<float> body(std::size_t count) {
  std::vector<float> vertices(3 * count);
  std::mt19937 rng(1);
  std::uniform_real_distribution<Real> unit(0, 1);
  for (std::size_t i = 0; i < count; ++i) {
    const Real a = 2 * kPi * unit(rng), r = 0.3 * unit(rng);
    vertices[3 * i] = static_cast<float>(-0.1 + 4.2 * Real(i) / Real(count));  // mesh order follows the body
    vertices[3 * i + 1] = static_cast<float>(r * std::cos(a));
    vertices[3 * i + 2] = static_cast<float>(r * std::sin(a));
  }
  return vertices;
}

// Reports the time per vertex beside the time per call.
void per_vertex(benchmark::State& state, std::size_t count) {
  state.counters["ns_per_vertex"] =
      benchmark::Counter(double(count), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void deform(benchmark::State& state, unsigned threads) {
  const std::size_t count = static_cast<std::size_t>(state.range(0));
  const std::vector<float> vertices = body(count);
  const AxisBinding binding(axis(0), vertices.data(), count, {}, std::nullopt);
  std::vector<float> out(3 * count);
  const Vec3List bent = axis(1.3);
  for (auto _ : state) {
    binding.deform(bent, {}, std::nullopt, out.data(), threads);
    benchmark::DoNotOptimize(out.data());
  }
  per_vertex(state, count);
}

// What the add-on runs for a bake or Apply: the packed (s, u, v) coordinates the mesh keeps
// (docs/algorithms.md §1.6), the frame table made once per frame as the handler does.
void deform_packed_coordinates(benchmark::State& state, unsigned threads) {
  const std::size_t count = static_cast<std::size_t>(state.range(0));
  const std::vector<float> vertices = body(count);
  const AxisBinding binding(axis(0), vertices.data(), count, {}, std::nullopt);
  const float end_scale = 1.0f;
  std::vector<float> packed(3 * count), out(3 * count);
  binding.packed_coordinates(end_scale, packed.data());
  FrameTable table;
  binding.frame_table(axis(1.3), {}, std::nullopt, table);
  for (auto _ : state) {
    deform_packed(table, packed.data(), count, end_scale, out.data(), threads);
    benchmark::DoNotOptimize(out.data());
  }
  per_vertex(state, count);
}

void BM_DeformAllCores(benchmark::State& state) { deform(state, 0); }
void BM_DeformOneThread(benchmark::State& state) { deform(state, 1); }
void BM_DeformPackedAllCores(benchmark::State& state) { deform_packed_coordinates(state, 0); }
void BM_DeformPackedOneThread(benchmark::State& state) { deform_packed_coordinates(state, 1); }

void BM_Bind(benchmark::State& state) {
  const std::size_t count = static_cast<std::size_t>(state.range(0));
  const std::vector<float> vertices = body(count);
  for (auto _ : state) {
    AxisBinding binding(axis(0), vertices.data(), count, {}, std::nullopt);
    benchmark::DoNotOptimize(binding.coordinates().data());
  }
  per_vertex(state, count);
}

// The fixed per-call cost: sampling the moved curve and its frames (1025 samples).
void BM_FrameTable(benchmark::State& state) {
  const Vec3List bent = axis(1.3);
  for (auto _ : state) {
    FrameList frames = axis_frames(bent, {}, std::nullopt, kTableSegments + 1);
    benchmark::DoNotOptimize(frames.data());
  }
}

}  // namespace

BENCHMARK(BM_DeformAllCores)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Arg(4'000'000)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_DeformOneThread)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Arg(4'000'000)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_DeformPackedAllCores)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_DeformPackedOneThread)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_Bind)->Arg(100'000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FrameTable)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_MAIN();
