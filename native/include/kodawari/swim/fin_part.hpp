// One fin part bound for motion (docs/algorithms.md §2.4). Replaces a
// per-fin FFD: every fin vertex swings as if hinged at its OWN root point (the
// lever is its reach across the fin, along the fin's outward direction), with the
// motion's angle faded in by a smoothstep weight that rises from 0 on the body to 1
// at `fade` reach. The swing is bent along each line across the fin (the integral of
// the faded rotation), so the fade itself stretches no line; neighbouring vertices get
// nearly the same rotation and a long-based fin (dorsal, anal) never swings its base
// ends away from the body. An undulation's slope is held under 0.8; a TWIST is held
// to max_roll (the fade shears under 0.35); feathering is not held (a rowing blade
// must turn edge-on; the caller holds it on fins that do not row).
#pragma once

#include <cstddef>
#include <vector>

#include "kodawari/common.hpp"
#include "kodawari/swim/fin_motion.hpp"

namespace kodawari::swim {

struct FinPartRest {
  Vec3 root{0, 0, 0};        // where the part meets the body (centroid of its root row)
  Vec3 outward{1, 0, 0};     // unit, root → tip
  RootFrame frame;           // the body's tailward tangent, side and up at the root
  Real height = 1;           // reach range root → rim (length units)
  Real base_length = 1;      // along the body (UNDULATE's wave runs along it)
  Real base_front = 0;       // tangent coordinate of the base's front end
};

// The unit axis a FLAP or UP_DOWN swing turns a part about (docs/algorithms.md §2.4):
// FLAP about outward × tangent (the body's up when the fin lies along the body),
// UP_DOWN about the body's tangent (its side when the fin lies along the body).
// Zero for TWIST and UNDULATE, which do not swing.
Vec3 swing_hinge(FinMotion motion, const Vec3& outward, const RootFrame& frame);

// The unit direction a swing moves the part's lines in (hinge × outward); zero when the
// motion does not swing.
Vec3 swing_direction(FinMotion motion, const Vec3& outward, const RootFrame& frame);

class FinPartBinding {
 public:
  // points: M rest positions; reach: M path lengths across the fin from the body
  // (0 at the root); weight: M weights in [0, 1] (the fin's vertex-group weight);
  // fade: the reach over which the motion fades in from the body (smoothstep); 0: none,
  // the weights are used as given.
  FinPartBinding(const Vec3List& points, const std::vector<Real>& reach, const std::vector<Real>& weight,
                 const FinPartRest& rest, Real fade = 0);

  std::size_t count() const { return reach_.size(); }

  // Writes M displacements (xyz floats) of the part for a phase, turned by
  // `body_rotation` (the body's rotation at the root, rest → now).
  void displace(const FinWave& wave, Real phase, const Mat3& body_rotation, float* out) const;

  // swing_direction for this part.
  Vec3 swing_direction(FinMotion motion) const { return swim::swing_direction(motion, rest_.outward, rest_.frame); }

  // The largest roll (twist / feathering) and undulation amplitude (length units)
  // the fade allows without shearing the mesh by more than 0.35.
  Real max_roll() const { return max_roll_; }
  // The largest feathering roll of a rowing fin (pectoral, pelvic): a looser shear, 0.85,
  // since a rowing blade must turn nearly edge-on; still held on a stubby fin whose fade
  // is short beside its width (a 0.5 rad roll stretched a small eel pectoral 1.9×).
  Real max_feather() const { return max_feather_; }
  Real max_undulation() const { return max_undulation_; }

 private:
  Vec3List across_;            // offset from the part's centre line, perpendicular to `outward`
  std::vector<Real> reach_, weight_, group_, along_, height_;
  FinPartRest rest_;
  Real fade_ = 0;
  Real max_roll_ = 0, max_feather_ = 0, max_undulation_ = 0;
};

// Nearest rotation to the map taking the rest probe arms to the current ones
// (polar decomposition): rest/now hold 4 points each, a root and its three arms.
Mat3 probe_rotation(const Vec3List& rest, const Vec3List& now);

}  // namespace kodawari::swim
