// Fin axis motion (docs/algorithms.md §2.4): a small control axis per fin, root first,
// whose first points are clustered at the root and stay fixed (so the fin never
// tears from the body) while the outer points rotate about the root.
#pragma once

#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::swim {

enum class FinMotion { Flap, UpDown, Twist, Undulate };

struct FinWave {
  FinMotion motion = FinMotion::Flap;
  Real amplitude = 0.5;    // radians for FLAP/UP_DOWN/TWIST; fraction of the axis length for UNDULATE
  Real feathering = 0.0;   // FLAP only: blade roll (radians) between the power and recovery strokes
  bool feather_on_power = false;  // true: roll mid-power-stroke (blade modelled edge-on to the stroke);
                                  // false: roll mid-recovery (blade modelled across the stroke)
  Real wavelength = 1.0;   // UNDULATE only: in fin-base lengths
  int fixed_count = 3;     // leading control points that never move (seed: 3 of 5)
};

// Unit direction the FLAP stroke moves the fin tip in at the power stroke (tailward
// for a fin sticking out of the body), for the caller to compare with the blade.
Vec3 flap_stroke_direction(const Vec3& fin_axis, const struct RootFrame& frame);

// The body's frame at the fin root: unit tailward tangent, side and up (right-handed
// or not, only used as directions).
struct RootFrame {
  Vec3 tangent{1, 0, 0};
  Vec3 side{0, 1, 0};
  Vec3 up{0, 0, 1};
};

struct FinPose {
  Vec3List points;           // moved control points, in the same (rest) space as the input
  std::vector<Real> twist;   // per-control-point roll about the fin axis (radians) for the FFD
};

// Moves a fin's rest control axis for one phase, in rest space (the caller then
// carries the result with the body). FLAP rotates the outer points so the tip
// moves fore/aft (sideways for a fin along the body, e.g. caudal) with feathering
// roll; UP_DOWN rotates them about the body tangent; TWIST rolls them about the
// fin axis; UNDULATE displaces every point sideways by a wave travelling along
// the axis (a fin base running head→tail, dorsal and anal fins).
FinPose fin_axis(const Vec3List& rest, const RootFrame& frame, const FinWave& wave, Real phase);

// Rotation about a unit axis (Rodrigues).
Mat3 axis_rotation(const Vec3& unit_axis, Real angle);

}  // namespace kodawari::swim
