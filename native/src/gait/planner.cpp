// The whole bake (seed 3.1 and 3.3), stage by stage; each stage is its own file
// (bake_stages.hpp lists them).
#include "kodawari/gait/planner.hpp"

#include "bake_stages.hpp"

namespace kodawari::gait {

BakeOutput bake_gait(const BakeInput& in) {
  const int frames = static_cast<int>(in.target_speed.size());
  BakeOutput out;
  out.frames = frames;
  if (frames == 0) return out;

  const stages::LegGeometry legs = stages::measure_legs(in.rig, in.table);
  out.bones = legs.bones;
  out.reach.assign(legs.reach.begin(), legs.reach.end());
  const stages::BodyTrack track = stages::plan_body_track(in, legs);
  const stages::Footfalls feet = stages::plan_footfalls(in, legs, track);
  const stages::BodyHeight height = stages::plan_body_height(in, legs, track, feet);

  out.angles.assign(static_cast<std::size_t>(frames) * out.bones, 0);
  out.body_location.assign(static_cast<std::size_t>(frames) * 3, 0);
  out.body_rotation.assign(static_cast<std::size_t>(frames) * 4, 0);
  out.contacts.assign(feet.contact.begin(), feet.contact.end());
  out.feet_planned.assign(static_cast<std::size_t>(frames) * 12, 0);
  out.feet.assign(static_cast<std::size_t>(frames) * 12, 0);
  out.roots.assign(static_cast<std::size_t>(frames) * 12, 0);
  out.headings.assign(static_cast<std::size_t>(frames) * 3, 0);
  out.gait.assign(frames, 0);
  out.speed.assign(frames, 0);
  out.ik_error.assign(static_cast<std::size_t>(frames) * 4, 0);

  const stages::BodyPoses poses = stages::pose_body(in, legs, track, height, out);
  stages::solve_legs(in, legs, feet, poses, out);
  forward_kinematics(in.rig, frames, out.angles.data(), out.body_location.data(), out.body_rotation.data(),
                     out.feet.data(), out.roots.data());
  return out;
}

}  // namespace kodawari::gait
