// The fish body wave (docs/algorithms.md §2.1): a sine wave travels head→tail along the
// control axis and its amplitude grows toward the tail. Stateless: the caller
// passes the ACCUMULATED phase (φ += ω·dt, docs/algorithms.md §2.2), never ω·t,
// so an animated frequency never makes the wave jump.
#pragma once

#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::swim {

struct BodyWave {
  Real wavelength = 1.0;       // in body lengths
  Real amplitude = 0.1;        // tail-tip peak amplitude, fraction of body length
  Real amplitude_head = 0.0;   // snout peak amplitude, fraction of body length
  Real envelope_start = 0.0;   // fraction of the body (from the snout) where growth begins
  Real envelope_power = 1.0;   // shape of the growth from envelope_start to the tail
  Real phase_offset = 0.0;     // radians, added to the accumulated phase
  bool preserve_length = true; // keep control-point distances (docs/algorithms.md §2.3)
};

// Peak amplitude (fraction of body length) at body fraction s in [0, 1].
Real wave_envelope(const BodyWave& wave, Real s);

// Lateral offset (fraction of body length) at body fraction s for the phase:
//   y(s, φ) = A(s) · sin(φ + phase_offset − 2π s / λ)
// Crests move tailward as φ grows.
Real wave_offset(const BodyWave& wave, Real s, Real phase);

// Fractions of the rest polygon's arc length at each control point (0 at the head, 1 at the tail).
std::vector<Real> arc_fractions(const Vec3List& points);

// Control-point offsets (length units, along the bend direction) whose clamped cubic
// B-spline follows the wave y(s, φ) of the rest curve's arc fraction s: a least-squares
// fit over 96 curve samples (fewer than 4 points: the wave at the points themselves).
std::vector<Real> fitted_offsets(const Vec3List& rest, Real body_length, const BodyWave& wave, Real phase);

// Control points of the swimming body axis for one phase. `bend_direction` is the
// unit direction the wave displaces points in (lateral or dorsoventral);
// `body_length` scales the amplitudes. With preserve_length the displacement along
// bend_direction still follows the wave (a few correction passes), while the points
// draw in along the body, keeping their distances (ffd::preserve_lengths_from_head,
// the seed's distance-keeping pass from the head) scaled by the one factor that gives
// the B-spline curve, and so the body, its rest arc length.
Vec3List body_axis(const Vec3List& rest, const Vec3& bend_direction, Real body_length, const BodyWave& wave,
                   Real phase);

// Integrates a sampled frequency (Hz) with the trapezoid rule into phases
// (radians): phase[0] = phase0, phase[k] = phase[k-1] + π (f[k-1] + f[k]) dt.
std::vector<Real> accumulate_phase(const std::vector<Real>& frequencies, Real dt, Real phase0);

}  // namespace kodawari::swim
