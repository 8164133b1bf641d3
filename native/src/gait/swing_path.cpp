#include "kodawari/gait/swing_path.hpp"

#include <algorithm>
#include <cmath>

namespace kodawari::gait {

Real swing_progress(Real s, Real ease) {
  s = std::clamp(s, Real(0), Real(1));
  auto ramp = [ease](Real x) { return x / 2 - ease / (2 * kPi) * std::sin(kPi * x / ease); };
  const Real total = 1 - ease;
  if (s <= ease) return ramp(s) / total;
  if (s >= 1 - ease) return 1 - ramp(1 - s) / total;
  return (ease / 2 + (s - ease)) / total;
}

// While a foot speeds up from rest its root runs on at v: the foot lags by about
// 0.65 v t_ease. The ease is shortened at speed so the lag stays near kEaseLag.
Real swing_ease(Real v, Real swing_time) {
  const Real t = v > 1e-6 ? kEaseLag / (0.65 * v) : swing_time;
  return std::clamp(t / swing_time, Real(0.01), kEaseMax);
}
Real ease_lag(Real v, Real swing_time) { return v * swing_ease(v, swing_time) * swing_time + 0.008; }

// 16 q^2 (1 - q)^2 (soft) or 27/4 q^2 (1 - q) (strike): 1 at their top, q = 1/2 or 2/3,
// which q = s^gamma puts at `peak`. The strike's gamma is under 1/2 for the fast gaits'
// early peaks, so its foot also leaves the ground fast (the limb folds at once).
Real swing_lift(Real s, Real peak, bool strike) {
  s = std::clamp(s, Real(0), Real(1));
  const Real top = strike ? Real(2) / 3 : Real(0.5);
  const Real gamma = std::log(top) / std::log(std::clamp(peak, Real(0.05), Real(0.95)));
  const Real q = std::pow(s, gamma);
  return strike ? Real(27) / 4 * q * q * (1 - q) : 16 * q * q * (1 - q) * (1 - q);
}

}  // namespace kodawari::gait
