// Native cost of the rod solver: 1,000 chains x 16 bones, 4 substeps per frame, the head
// swaying smoothly (Smooth), jumping back every second (the solver's worst case) or still
// with the hair at rest after 10 s of settling (Still: what a scene of resting hair costs).
// Reports time per frame and per particle-substep (items = particle-substeps).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "kodawari/rod/rod_system.hpp"

using namespace kodawari;
using namespace kodawari::rod;

namespace {

constexpr int kChains = 1000;
constexpr int kBones = 16;

enum class Head { Smooth, Sawtooth, Still };

// Smooth: the head sways on a sine (as characters move); Sawtooth: it jumps back by 0.4 m
// every 24 frames (every chain whips, the solver's worst case); Still: it holds still and the
// chains, horizontal at first, have 240 frames to come to rest before the timing starts.
void run_rods(benchmark::State& state, Head head) {
  const unsigned threads = static_cast<unsigned>(state.range(0));
  const std::size_t bone_count = 1 + kChains * kBones;
  RodSystem system(bone_count, threads);
  for (int c = 0; c < kChains; ++c) {
    RodDefinition rod;
    rod.parent_bone = 0;
    rod.reference_bone = 0;
    rod.geometry.offsets.push_back(Vec3(0.001 * c, 0.3, 0));
    for (int b = 0; b < kBones; ++b) {
      rod.bones.push_back(1 + c * kBones + b);
      rod.geometry.offsets.push_back(Vec3(0, 0.02, 0));
    }
    rod.geometry.rest_rotations.assign(kBones, Quat::Identity());
    rod.params.substeps = 4;
    system.add_rod(rod);
  }
  std::vector<float> matrices(16 * bone_count, 0.0f);
  for (std::size_t b = 0; b < bone_count; ++b) {
    for (int d = 0; d < 4; ++d) matrices[16 * b + 5 * d] = 1.0f;
  }
  std::vector<float> rotations(4 * bone_count, 0.0f);
  FrameInput input;
  input.bone_matrices = matrices.data();
  input.bone_count = bone_count;
  input.has_camera = true;
  input.camera = Vec3(0, -5, 1.7);
  system.reset(input, rotations.data());
  int frame = 0;
  if (head == Head::Still) {
    for (; frame < 240; ++frame) {
      input.time = (frame + 1) / 24.0;
      system.step(input, rotations.data());
    }
  }
  for (auto _ : state) {
    if (head == Head::Smooth) {
      matrices[12] = 0.2f * static_cast<float>(std::sin(frame * 2.0 * 3.14159265 / 24.0));  // the head sways
    } else if (head == Head::Sawtooth) {
      matrices[12] = 0.2f * static_cast<float>((frame % 24) - 12) / 12.0f;
    }
    input.time = ++frame / 24.0;
    system.step(input, rotations.data());
    benchmark::DoNotOptimize(rotations.data());
  }
  state.SetItemsProcessed(state.iterations() * kChains * kBones * 4);
  state.counters["us_per_bone"] =
      benchmark::Counter(static_cast<double>(kChains * kBones), benchmark::Counter::kIsIterationInvariantRate |
                                                                    benchmark::Counter::kInvert);
}

void BM_RodSystemStep(benchmark::State& state) { run_rods(state, Head::Sawtooth); }
void BM_RodSystemStepSmooth(benchmark::State& state) { run_rods(state, Head::Smooth); }
void BM_RodSystemStepStill(benchmark::State& state) { run_rods(state, Head::Still); }

}  // namespace

BENCHMARK(BM_RodSystemStepSmooth)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RodSystemStep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RodSystemStepStill)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
