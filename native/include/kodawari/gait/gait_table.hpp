// The gait table (seed section 3, "Gaits"): per gait its duty factor, phase offsets,
// swing time, swing-height profile, body bob and the speed band AUTO uses.
#pragma once

#include <array>
#include <string>

#include "kodawari/common.hpp"

namespace kodawari::gait {

enum class Gait : int { Walk = 0, Trot = 1, Canter = 2, Gallop = 3, GallopRotary = 4 };
constexpr int kGaitCount = 5;

// Leg order everywhere in the gait code (and in the contact channels): LF, RF, LH, RH.
enum LegIndex : int { kLF = 0, kRF = 1, kLH = 2, kRH = 3 };
constexpr int kLegCount = 4;

inline bool is_fore(int leg) { return leg == kLF || leg == kRF; }

struct GaitParams {
  Real duty_factor = 0.5;       // alpha: stance time / cycle time (at the bottom of the band)
  Real duty_factor_top = 0.5;   // alpha at the top of the band: falls with speed in the gallop
  Real phase_fore_hind = 0.5;   // D1 (seed 3.3): LF lifts off D1 of a cycle after LH
  Real phase_left_right = 0.5;  // D2: RH lifts off D2 after LH
  Real swing_time = 0.3;        // P, seconds (constant per animal, seed 2.2)
  Real swing_height = 0.15;     // peak foot lift, m
  Real swing_peak = 0.4;        // where in the swing (0..1) the foot is highest
  Real bob = 0.03;              // body dip amplitude, m
  Real bobs_per_cycle = 2;      // body dips per stride (2 walk/trot, 1 canter/gallop)
  Real speed_max = 2.0;         // AUTO: top of this gait's band, m/s
  Real froude_max = 0.35;       // AUTO with Froude: top of the band as v^2/(g L)
  bool use_in_auto = true;
};

struct GaitTable {
  std::array<GaitParams, kGaitCount> gaits;
  bool use_froude = false;  // AUTO bands by Froude number instead of speed
  Real hysteresis = 0.15;   // AUTO: a band is left only this far (m/s) past its edge
  Real reach = 0.5;         // fore-aft reach of a foot around its leg root, x leg length
                            // (horse: 0.8 m for a 1.6 m leg, seed 4.3)
};

constexpr const char* kGaitNames[kGaitCount] = {"WALK", "TROT", "CANTER", "GALLOP", "GALLOP_ROTARY"};
constexpr const char* kLegNames[kLegCount] = {"LF", "RF", "LH", "RH"};

// Hip height (m) of the horse the default table is tuned on: the sample Thoroughbred
// (1.406 m; Blender's Rigify horse metarig stands 1.408 m at the hip).
constexpr Real kHorseLegLength = 1.406;

// The table for an animal whose hip stands `leg_length` m high, by dynamic similarity
// (Alexander & Jayes 1983; docs/algorithms.md §4.12): at equal Froude number
// v^2/(g L) animals use the same duty factors and phases, strides scale with L, so
// speeds scale with sqrt(L / L0), times with sqrt(L / L0), heights with L / L0.
// Froude band tops are dimensionless and stay.
GaitTable scale_table(const GaitTable& table, Real leg_length, Real reference = kHorseLegLength);

// The horse defaults: the seed's table, with the canter and gallop tuned to the
// literature notes (see gait_table.cpp for the numbers and why).
GaitTable horse_gait_table();

// Cycle time T = P / (1 - alpha)  (seed 3.2).
Real cycle_time(const GaitParams& params);
Real cycle_time(Real swing_time, Real duty_factor);

// Bottom of a gait's band in m/s: the highest AUTO band top below its own top (0 for the first).
Real band_bottom(const GaitTable& table, Gait gait, Real leg_length);

// The duty factor at `speed`: duty_factor at the bottom of the band, duty_factor_top at
// its top, and in between the one that keeps the stance length (distance travelled
// over a planted foot) interpolated linearly, clamped outside. Gallops use it: the
// stance shortens with speed, so the stride at low gallop speed is longer than a fixed
// alpha gives (Thoroughbreds: alpha ~0.32 at 9 m/s, ~0.2 at 17 m/s).
Real duty_at(const GaitTable& table, Gait gait, Real speed, Real leg_length);

// The speed-range rule: the first frame whose speed is past the range of its gait mode
// (-1 AUTO: the table's top), or -1 when every frame is within range.
struct SpeedProblem {
  int frame = -1;
  Real top = 0;
};
SpeedProblem check_speeds(const GaitTable& table, const Real* speed, const int* mode, int frames, Real leg_length);

// Lift-off phase of `leg` in the cycle, relative to LH (seed: LH 0, LF D1, RH D2,
// RF D1 + D2; the rotary gallop swaps the fore pair: RF D1, LF D1 + D2). In [0, 1).
Real leg_phase(const GaitParams& params, Gait gait, int leg);

// Seed eq. 3.6: swing distance after a speed change V -> V' made C seconds before
// this lift-off, with t seconds added to the stance: S = V'P/(1-alpha) + (V'-V)C + V't.
Real seed_swing_distance(Real speed_new, Real speed_old, Real swing_time, Real duty_factor, Real since_change,
                         Real added_time);

// Top of a gait's band in m/s (Froude bands converted with the leg length).
Real band_top(const GaitTable& table, Gait gait, Real leg_length);

// The fastest speed the table covers: AUTO (gait < 0) or one fixed gait.
Real table_speed_max(const GaitTable& table, int gait, Real leg_length);

// AUTO choice with hysteresis: stays in `current` while speed is within its band
// widened by the hysteresis; otherwise the lowest AUTO gait whose band holds speed.
Gait select_gait(const GaitTable& table, Real speed, int current, Real leg_length);

// Empty when the table is usable, else a sentence saying what is wrong.
std::string validate_table(const GaitTable& table);

}  // namespace kodawari::gait
