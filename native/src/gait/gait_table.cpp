#include "kodawari/gait/gait_table.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace kodawari::gait {

namespace {
constexpr Real kGravity = 9.81;

GaitParams make(Real duty, Real d1, Real d2, Real swing, Real height, Real peak, Real bob, Real bobs,
                Real speed_max, bool auto_gait) {
  GaitParams p;
  p.duty_factor = duty;
  p.duty_factor_top = duty;
  p.phase_fore_hind = d1;
  p.phase_left_right = d2;
  p.swing_time = swing;
  p.swing_height = height;
  p.swing_peak = peak;
  p.bob = bob;
  p.bobs_per_cycle = bobs;
  p.speed_max = speed_max;
  // Froude bands for the horse's leg: Fr = v^2 / (g L); walk->trot at Fr ~ 0.25-0.35
  // (literature notes).
  p.froude_max = speed_max * speed_max / (kGravity * kHorseLegLength);
  p.use_in_auto = auto_gait;
  return p;
}
}  // namespace

GaitTable horse_gait_table() {
  GaitTable t;
  // WALK and TROT: the seed's numbers (P = 0.3 s; alpha 0.7, 0.5; phases (0.2, 0.5),
  // (0.5, 0.5)). Trot at 5 m/s strides 3.0 m (measured 3.04 m).
  t.gaits[0] = make(0.7, 0.2, 0.5, 0.3, 0.12, 0.45, 0.02, 2, 1.9, true);
  t.gaits[1] = make(0.5, 0.5, 0.5, 0.3, 0.18, 0.40, 0.04, 2, 5.0, true);
  // CANTER: the seed's P = 0.3 s, alpha = 0.3 give a 2.14 m stride at 5 m/s where
  // horses measure 2.68 m. We keep the seed's principle (swing time constant, stance
  // absorbs speed) with the literature's swing of 0.33 s and raise the duty factor to
  // 0.385: T = 0.33 / 0.615 = 0.537 s, stride at 5 m/s = 2.68 m.
  t.gaits[2] = make(0.385, 0.2, 0.2, 0.33, 0.22, 0.40, 0.05, 1, 7.0, true);
  // GALLOP (transverse): the seed's alpha = 0.25, P = 0.3 s put a planted hoof 0.85 m
  // behind its root at 17 m/s, past the seed's own 0.8 m reach. The literature
  // (Thoroughbreds: swing 0.33-0.36 s, duty factor down to ~0.2, stride 7.1 m at
  // 17 m/s) gives alpha = 0.2, P = 0.33 s: stride 7.0 m at 17 m/s, hoof within 0.7 m.
  // The duty factor falls with speed (stance 131 -> 77 ms from 9 to 17 m/s): alpha 0.35
  // at the band's bottom (7 m/s) to 0.185 at its top (18 m/s) with the stance length
  // in between (duty_at), i.e. 0.30 at 9 m/s (stride 4.2 m; measured 4.5 m, 3.7 m with
  // a fixed 0.2) and 0.19 at 17 m/s (stride 7.0 m; measured 7.1 m). Longer stances at
  // 9 m/s would put a planted hoof past the leg's reach.
  t.gaits[3] = make(0.35, 0.35, 0.2, 0.33, 0.25, 0.35, 0.05, 1, 18.0, true);
  t.gaits[3].duty_factor_top = 0.185;
  // Rotary gallop (LH, RH, RF, LF): horses use it to accelerate or change lead; AUTO
  // does not pick it for the horse (a dog's table does).
  t.gaits[4] = make(0.35, 0.35, 0.2, 0.33, 0.25, 0.35, 0.05, 1, 18.0, false);
  t.gaits[4].duty_factor_top = 0.185;
  return t;
}

GaitTable scale_table(const GaitTable& table, Real leg_length, Real reference) {
  GaitTable t = table;
  if (!(leg_length > 0) || !(reference > 0)) return t;
  const Real length = leg_length / reference, time = std::sqrt(length), speed = std::sqrt(length);
  for (GaitParams& p : t.gaits) {
    p.swing_time *= time;
    p.swing_height *= length;
    p.bob *= length;
    p.speed_max *= speed;
  }
  t.hysteresis *= speed;
  return t;
}

Real cycle_time(Real swing_time, Real duty_factor) { return swing_time / (Real(1) - duty_factor); }
Real cycle_time(const GaitParams& params) { return cycle_time(params.swing_time, params.duty_factor); }

Real band_bottom(const GaitTable& table, Gait gait, Real leg_length) {
  // The highest AUTO band top below this gait's top: a gait AUTO does not pick (the
  // horse's rotary gallop) shares the band of its AUTO twin.
  const Real top = band_top(table, gait, leg_length);
  Real bottom = 0;
  for (int g = 0; g < kGaitCount; ++g) {
    if (!table.gaits[g].use_in_auto) continue;
    const Real t = band_top(table, static_cast<Gait>(g), leg_length);
    if (t < top - 1e-9) bottom = std::max(bottom, t);
  }
  return bottom;
}

Real duty_at(const GaitTable& table, Gait gait, Real speed, Real leg_length) {
  const GaitParams& p = table.gaits[static_cast<int>(gait)];
  if (p.duty_factor_top == p.duty_factor) return p.duty_factor;
  // The stance's length (distance the body travels over a planted foot) is what the
  // leg's reach bounds; it changes little with speed (Thoroughbreds: 1.2-1.3 m from 9
  // to 17 m/s). So the stance length is interpolated between the band's ends, and the
  // duty factor follows: alpha = d / (d + v P).
  const Real lo = band_bottom(table, gait, leg_length), hi = band_top(table, gait, leg_length);
  const Real P = p.swing_time;
  auto stance_length = [P](Real v, Real a) { return v * P * a / (1 - a); };
  const Real d_lo = stance_length(lo, p.duty_factor), d_hi = stance_length(hi, p.duty_factor_top);
  const Real w = hi > lo ? std::clamp((speed - lo) / (hi - lo), Real(0), Real(1)) : Real(0);
  const Real d = d_lo + w * (d_hi - d_lo);
  const Real alpha = speed * P + d > 0 ? d / (d + speed * P) : p.duty_factor;
  return std::clamp(alpha, std::min(p.duty_factor, p.duty_factor_top), std::max(p.duty_factor, p.duty_factor_top));
}

SpeedProblem check_speeds(const GaitTable& table, const Real* speed, const int* mode, int frames, Real leg_length) {
  SpeedProblem problem;
  for (int f = 0; f < frames; ++f) {
    const Real top = table_speed_max(table, mode[f], leg_length);
    if (speed[f] > top + 1e-6) {
      problem.frame = f;
      problem.top = top;
      return problem;
    }
  }
  return problem;
}

Real leg_phase(const GaitParams& params, Gait gait, int leg) {
  const Real d1 = params.phase_fore_hind;
  const Real d2 = params.phase_left_right;
  const bool rotary = gait == Gait::GallopRotary;
  Real phase = 0;
  switch (leg) {
    case kLH: phase = 0; break;
    case kRH: phase = d2; break;
    case kLF: phase = rotary ? d1 + d2 : d1; break;
    case kRF: phase = rotary ? d1 : d1 + d2; break;
    default: break;
  }
  return phase - std::floor(phase);
}

Real seed_swing_distance(Real speed_new, Real speed_old, Real swing_time, Real duty_factor, Real since_change,
                         Real added_time) {
  return speed_new * swing_time / (Real(1) - duty_factor) + (speed_new - speed_old) * since_change +
         speed_new * added_time;
}

Real band_top(const GaitTable& table, Gait gait, Real leg_length) {
  const GaitParams& p = table.gaits[static_cast<int>(gait)];
  if (table.use_froude) return std::sqrt(std::max(Real(0), p.froude_max) * kGravity * leg_length);
  return p.speed_max;
}

Real table_speed_max(const GaitTable& table, int gait, Real leg_length) {
  if (gait >= 0 && gait < kGaitCount) return band_top(table, static_cast<Gait>(gait), leg_length);
  Real top = 0;
  for (int g = 0; g < kGaitCount; ++g) {
    if (table.gaits[g].use_in_auto) top = std::max(top, band_top(table, static_cast<Gait>(g), leg_length));
  }
  return top;
}

Gait select_gait(const GaitTable& table, Real speed, int current, Real leg_length) {
  int nominal = -1, last_auto = -1;
  Real lower = 0;  // top of the previous AUTO gait's band
  for (int g = 0; g < kGaitCount; ++g) {
    if (!table.gaits[g].use_in_auto) continue;
    const Real top = band_top(table, static_cast<Gait>(g), leg_length);
    // Hysteresis: the current gait holds until the speed is past its band by this much.
    if (g == current && speed >= lower - table.hysteresis && speed <= top + table.hysteresis) {
      return static_cast<Gait>(g);
    }
    if (nominal < 0 && speed <= top) nominal = g;
    last_auto = g;
    lower = top;
  }
  if (nominal < 0) nominal = last_auto < 0 ? 0 : last_auto;
  return static_cast<Gait>(nominal);
}

std::string validate_table(const GaitTable& table) {
  std::ostringstream why;
  Real previous_top = -1;
  int auto_count = 0;
  for (int g = 0; g < kGaitCount; ++g) {
    const GaitParams& p = table.gaits[g];
    const char* name = kGaitNames[g];
    auto finite = [](Real v) { return std::isfinite(v); };
    if (!finite(p.duty_factor) || p.duty_factor < 0.05 || p.duty_factor > 0.95 || !finite(p.duty_factor_top) ||
        p.duty_factor_top < 0.05 || p.duty_factor_top > 0.95) {
      why << name << ": duty factor must be between 0.05 and 0.95";
    } else if (!finite(p.swing_time) || p.swing_time < 0.05 || p.swing_time > 5) {
      why << name << ": swing time must be between 0.05 and 5 s";
    } else if (!finite(p.phase_fore_hind) || !finite(p.phase_left_right) || p.phase_fore_hind < 0 ||
               p.phase_fore_hind > 1 || p.phase_left_right < 0 || p.phase_left_right > 1) {
      why << name << ": phase offsets must be between 0 and 1";
    } else if (!finite(p.swing_height) || p.swing_height < 0 || !finite(p.swing_peak) || p.swing_peak < 0.05 ||
               p.swing_peak > 0.95) {
      why << name << ": swing height must be >= 0 and its peak between 0.05 and 0.95";
    } else if (!finite(p.bob) || p.bob < 0 || !finite(p.bobs_per_cycle) || p.bobs_per_cycle < 0) {
      why << name << ": body bob must be >= 0";
    } else if (p.use_in_auto) {
      const Real top = table.use_froude ? p.froude_max : p.speed_max;
      if (!finite(top) || top <= previous_top || top <= 0) {
        why << name << ": its AUTO band top must be above the slower gaits' (" << (table.use_froude ? "Froude" : "m/s")
            << ")";
      }
      previous_top = top;
      ++auto_count;
    }
    if (!why.str().empty()) return why.str();
  }
  if (auto_count == 0) return "the gait table has no gait for AUTO";
  if (!std::isfinite(table.hysteresis) || table.hysteresis < 0) return "hysteresis must be >= 0";
  if (!std::isfinite(table.reach) || table.reach <= 0 || table.reach > 1) return "reach must be in (0, 1] of the leg length";
  return {};
}

}  // namespace kodawari::gait
