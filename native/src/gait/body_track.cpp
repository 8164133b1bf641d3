// The body over the ground on the planner's fine grid: speed with the acceleration
// limit, the gait AUTO chooses (with hysteresis), and head and heading along the path.
#include <cmath>

#include "bake_stages.hpp"

namespace kodawari::gait::stages {

namespace {

constexpr Real kSubstepRate = 480;  // planner grid, Hz: events land within ~2 ms

// A polyline by arc length, carried on straight past both ends.
struct Path {
  std::vector<Vec2d> points;
  std::vector<Real> arc;
  bool empty() const { return points.size() < 2; }
  Vec2d at(Real s) const {
    if (s <= 0) return points.front() + (points[1] - points[0]).normalized() * s;
    if (s >= arc.back()) {
      const Vec2d d = (points.back() - points[points.size() - 2]).normalized();
      return points.back() + d * (s - arc.back());
    }
    const auto it = std::upper_bound(arc.begin(), arc.end(), s);
    const std::size_t i = static_cast<std::size_t>(it - arc.begin()) - 1;
    const Real span = arc[i + 1] - arc[i];
    const Real w = span > 0 ? (s - arc[i]) / span : 0;
    return points[i] + w * (points[i + 1] - points[i]);
  }
};

Path make_path(const Vec3List& polyline) {
  Path path;
  for (const Vec3& p : polyline) {
    const Vec2d q = horizontal(p);
    if (!path.points.empty() && (q - path.points.back()).norm() < 1e-9) continue;
    path.points.push_back(q);
  }
  path.arc.assign(path.points.size(), 0);
  for (std::size_t i = 1; i < path.points.size(); ++i) {
    path.arc[i] = path.arc[i - 1] + (path.points[i] - path.points[i - 1]).norm();
  }
  return path;
}

Vec2d rotate2(const Vec2d& v, const Vec2d& from, const Vec2d& to) {
  // The rotation taking unit `from` to unit `to`, applied to v.
  const Real c = from.dot(to), s = from.x() * to.y() - from.y() * to.x();
  return Vec2d(c * v.x() - s * v.y(), s * v.x() + c * v.y());
}

}  // namespace

Vec2d BodyTrack::root_at(int leg, long k) const {
  const Frame2& b = at(k);
  return b.head + rotate2(horizontal(root_rel[leg]), forward, b.heading);
}

Vec2d BodyTrack::lateral_dir(long k) const {
  const Vec2d h = at(k).heading;
  return Vec2d(-h.y(), h.x());
}

BodyTrack plan_body_track(const BakeInput& in, const LegGeometry& legs) {
  const GaitTable& table = in.table;
  const int frames = static_cast<int>(in.target_speed.size());
  BodyTrack track;
  track.forward = horizontal(in.rig.forward);
  track.root_rel = legs.root_rel;
  track.substeps = std::max(1, static_cast<int>(std::ceil(kSubstepRate / in.fps - 1e-9)));
  track.dt = Real(1) / (in.fps * track.substeps);
  const int substeps = track.substeps;
  const Real dt = track.dt;
  track.last_step = static_cast<long>(frames - 1) * substeps;
  const long lookahead = static_cast<long>(std::ceil(3.0 / dt));  // plans look up to ~2 strides ahead
  const long steps = track.last_step + lookahead + 1;
  track.steps = steps;
  track.distance.resize(steps);
  track.speed.resize(steps);
  track.gait.resize(steps);
  track.body.resize(steps);
  Real v = std::max(Real(0), in.target_speed[0]);
  Real s = 0;
  int current = in.gait_mode[0] >= 0 ? in.gait_mode[0] : static_cast<int>(select_gait(table, v, -1, legs.leg_length));
  for (long k = 0; k < steps; ++k) {
    const Real frame = static_cast<Real>(k) / substeps;
    const int f0 = std::min(frames - 1, static_cast<int>(frame));
    const int f1 = std::min(frames - 1, f0 + 1);
    const Real w = std::min(Real(1), frame - f0);
    const Real target = std::max(Real(0), in.target_speed[f0] * (1 - w) + in.target_speed[f1] * w);
    if (k > 0) {
      const Real dv = std::clamp(target - v, -in.acceleration * dt, in.acceleration * dt);
      v = std::max(Real(0), v + dv);
      s += v * dt;
    }
    const int mode = in.gait_mode[f0];
    current = mode >= 0 ? mode : static_cast<int>(select_gait(table, v, current, legs.leg_length));
    track.speed[k] = v;
    track.distance[k] = s;
    track.gait[k] = current;
  }
  const Path path = make_path(in.path);
  const Vec2d F2 = track.forward;
  for (long k = 0; k < steps; ++k) {
    Frame2& b = track.body[k];
    if (path.empty()) {
      b.head = horizontal(in.rig.body_head) + F2 * track.distance[k];
      b.heading = F2;
    } else {
      b.head = path.at(track.distance[k]);
      const Vec2d d = path.at(track.distance[k] + 0.25) - path.at(track.distance[k] - 0.25);
      b.heading = d.norm() > 1e-9 ? Vec2d(d.normalized()) : F2;
    }
  }
  return track;
}

}  // namespace kodawari::gait::stages
