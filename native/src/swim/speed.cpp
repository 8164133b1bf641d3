#include "kodawari/swim/speed.hpp"

#include <algorithm>

namespace kodawari::swim {

Real bainbridge_speed(Real body_length, Real frequency) {
  return std::max(Real(0), Real(0.25) * body_length * (Real(3) * frequency - Real(4)));
}

bool bainbridge_applies(Real frequency) { return frequency >= kBainbridgeMinFrequency; }

Real strouhal_speed(Real frequency, Real peak_to_peak, Real strouhal) {
  if (strouhal <= Real(0)) return Real(0);
  return std::max(Real(0), frequency * peak_to_peak / strouhal);
}

Real fin_cruise_speed(Real body_length, Real frequency) {
  return std::max(Real(0), kFinStride * body_length * frequency);
}

Real swim_speed(SpeedMode mode, Real body_length, Real frequency, Real amplitude, Real strouhal) {
  if (mode == SpeedMode::None) return Real(0);
  const Real peak_to_peak = Real(2) * amplitude * body_length;
  // No body wave: a fin swimmer (ostraciiform, balistiform, labriform) goes by its fin beat.
  if (!(peak_to_peak > Real(1e-6) * body_length)) return fin_cruise_speed(body_length, frequency);
  switch (mode) {
    case SpeedMode::Bainbridge: {
      // Bainbridge's line was fitted to fish beating above ~5 Hz; wherever it leaves the
      // Strouhal band fish swim in (0.2-0.4, Taylor et al. 2003) — below that, or for a
      // small tail beat — the Strouhal model with the object's own number takes over.
      const Real fastest = strouhal_speed(frequency, peak_to_peak, kStrouhalLow);
      const Real slowest = strouhal_speed(frequency, peak_to_peak, kStrouhalHigh);
      const Real line = bainbridge_speed(body_length, frequency);
      return line >= slowest && line <= fastest ? line : strouhal_speed(frequency, peak_to_peak, strouhal);
    }
    case SpeedMode::Strouhal:
      return strouhal_speed(frequency, peak_to_peak, strouhal);
    case SpeedMode::None:
      break;
  }
  return Real(0);
}

}  // namespace kodawari::swim
