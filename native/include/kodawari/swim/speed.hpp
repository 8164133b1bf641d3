// How fast a fish swims for its tail beat (docs/algorithms.md §2.6).
#pragma once

#include "kodawari/common.hpp"

namespace kodawari::swim {

enum class SpeedMode { None, Bainbridge, Strouhal };

// Bainbridge (1958): V = ¼·L·(3f − 4), valid above ~5 Hz for small fish; never negative.
Real bainbridge_speed(Real body_length, Real frequency);

// Strouhal: St = f·A/U with A the tail's peak-to-peak excursion, so U = f·A/St.
Real strouhal_speed(Real frequency, Real peak_to_peak, Real strouhal);

// Speed for a mode; amplitude is the tail-tip PEAK amplitude as a fraction of body length.
Real swim_speed(SpeedMode mode, Real body_length, Real frequency, Real amplitude, Real strouhal);

}  // namespace kodawari::swim
