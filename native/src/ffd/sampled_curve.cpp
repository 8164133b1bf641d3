#include "kodawari/ffd/sampled_curve.hpp"

namespace kodawari::ffd {

UniformCurveSampler::UniformCurveSampler(int count, int samples) : count_(count) {
  basis_.resize(static_cast<std::size_t>(samples));
  for (int i = 0; i < samples; ++i) {
    const Real t = i == samples - 1 ? Real(1) : Real(i) / Real(samples - 1);
    basis_[static_cast<std::size_t>(i)] = cubic_basis(count, t);
  }
}

void UniformCurveSampler::sample(const Vec3List& points, const std::vector<Real>& twist, CurveSamples& out) const {
  const std::size_t samples = basis_.size();
  out.origin.resize(samples);
  out.tangent.resize(samples);
  out.roll.resize(twist.empty() ? 0 : samples);
  // Speeds below this fraction of the polygon's size count as a cusp.
  Real polygon = 0;
  for (std::size_t i = 0; i + 1 < points.size(); ++i) polygon += (points[i + 1] - points[i]).norm();
  const Real cusp_speed = Real(1e-9) * polygon;
  for (std::size_t i = 0; i < samples; ++i) {
    const CubicBasis& b = basis_[i];
    Vec3 position = Vec3::Zero(), derivative = Vec3::Zero();
    Real roll = 0;
    for (int j = 0; j < 4; ++j) {
      const Vec3& p = points[static_cast<std::size_t>(b.first + j)];
      position += b.value[j] * p;
      derivative += b.slope[j] * p;
      if (!twist.empty()) roll += b.value[j] * twist[static_cast<std::size_t>(b.first + j)];
    }
    out.origin[i] = position;
    const Real speed = derivative.norm();
    out.tangent[i] = speed > cusp_speed ? Vec3(derivative / speed) : Vec3::Zero();
    if (!twist.empty()) out.roll[i] = roll;
  }
  // A cusp (M' = 0, only when control points fold back on themselves): take
  // the chord across the neighbouring samples, else the first control leg.
  for (std::size_t i = 0; i < samples; ++i) {
    if (out.tangent[i].squaredNorm() > 0) continue;
    const Vec3 chord = out.origin[i + 1 < samples ? i + 1 : i] - out.origin[i > 0 ? i - 1 : i];
    out.tangent[i] = chord.norm() > cusp_speed ? Vec3(chord.normalized()) : Vec3((points[1] - points[0]).normalized());
  }
}

}  // namespace kodawari::ffd
