// How fast a fish swims for its tail beat (docs/algorithms.md §2.6).
#pragma once

#include "kodawari/common.hpp"

namespace kodawari::swim {

enum class SpeedMode { None, Bainbridge, Strouhal };

// Fish swim at Strouhal numbers St = f·A/U of 0.2-0.4 (Triantafyllou et al. 1993;
// Taylor, Nudds & Thomas 2003, Nature 425: 707).
constexpr Real kStrouhalLow = 0.2;
constexpr Real kStrouhalHigh = 0.4;
// Bainbridge (1958, J. Exp. Biol. 35: 109) fitted V = L(3f - 4)/4 to dace, trout and
// goldfish beating their tails above about 5 Hz.
constexpr Real kBainbridgeMinFrequency = 5.0;
// Fin (median/paired-fin) swimmers at cruise: about half a body length per fin beat
// (labriform wrasses ~1-3 L/s at 2-4 Hz, Walker & Westneat 2002; boxfish, Hove et al. 2001).
constexpr Real kFinStride = 0.5;

// Bainbridge (1958): V = ¼·L·(3f − 4); never negative.
Real bainbridge_speed(Real body_length, Real frequency);

// Whether the frequency lies where Bainbridge's line was fitted (f >= ~5 Hz).
bool bainbridge_applies(Real frequency);

// Strouhal: St = f·A/U with A the tail's peak-to-peak excursion, so U = f·A/St.
Real strouhal_speed(Real frequency, Real peak_to_peak, Real strouhal);

// A fin swimmer's cruise speed from its fin beat: kFinStride body lengths per beat.
Real fin_cruise_speed(Real body_length, Real frequency);

// Speed for a mode; amplitude is the tail-tip PEAK amplitude as a fraction of body
// length. With no body wave (amplitude 0: a fin swimmer) every mode gives the fin
// cruise speed; where BAINBRIDGE's line leaves the Strouhal band 0.2-0.4 it gives the
// STROUHAL speed for the object's own Strouhal number.
Real swim_speed(SpeedMode mode, Real body_length, Real frequency, Real amplitude, Real strouhal);

}  // namespace kodawari::swim
