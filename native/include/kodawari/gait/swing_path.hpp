// The path of a swinging foot (seed 3.1, 3.3: "a smooth path with the gait's height
// profile"): how far along the ground it is, and how high, at each moment of a swing.
#pragma once

#include "kodawari/common.hpp"

namespace kodawari::gait {

constexpr Real kEaseMax = 0.1;   // most of a swing spent speeding up / slowing down
constexpr Real kEaseLag = 0.02;  // m: how far a foot may lag (or lead) its root while it eases

// Share of the ground distance covered at swing time s in [0, 1]: velocity rises from 0
// over `ease` of the swing by a half cosine, holds, and falls the same way, so the foot
// leaves and lands at rest (no jump, no step in speed).
Real swing_progress(Real s, Real ease);

// The ease for a root moving at v: shortened at speed so the foot's lag behind its
// root while it speeds up stays near kEaseLag.
Real swing_ease(Real v, Real swing_time);

// How far a foot can be carried past its lift-off (or landing) point relative to the
// root while it eases: the planner keeps this much inside the reach.
Real ease_lag(Real v, Real swing_time);

// Height profile in [0, 1]: 0 at both ends, 1 at `peak`. A soft landing reaches the
// ground with zero vertical speed; a striking one (`strike`) comes down at speed, and
// lifts off fast (docs/algorithms.md §4.6).
Real swing_lift(Real s, Real peak, bool strike = false);

}  // namespace kodawari::gait
