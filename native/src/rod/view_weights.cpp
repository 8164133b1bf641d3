#include "kodawari/rod/view_weights.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kodawari::rod {

std::vector<Real> condition_weights(const std::vector<Real>& similarities, const std::vector<Real>& influences) {
  if (similarities.size() != influences.size()) {
    throw std::invalid_argument("similarities and influences must have the same length");
  }
  const std::size_t m = similarities.size();
  std::vector<Real> w(m + 1, Real(0));
  Real sum = 0;
  for (std::size_t i = 0; i < m; ++i) {
    if (!(influences[i] > 0)) throw std::invalid_argument("influences must be > 0");
    const Real s = std::clamp(similarities[i], Real(0), Real(1));
    w[i + 1] = std::pow(s, influences[i]);
    sum += w[i + 1];
  }
  if (sum >= 1) {
    for (std::size_t i = 1; i <= m; ++i) w[i] /= sum;
    sum = 1;
  }
  w[0] = 1 - sum;
  return w;
}

Real view_similarity(const Vec3& key_direction, const Vec3& view_direction) {
  return (key_direction.dot(view_direction) + 1) / 2;
}

Real pose_similarity(const Quat& key_rotation, const Quat& rotation) {
  const Real d = key_rotation.normalized().dot(rotation.normalized());
  return std::min(Real(1), d * d);
}

Real speed_similarity(Real key_speed, Real speed) {
  const Real scale = std::max(key_speed, Real(0.25));
  return std::exp(-std::abs(speed - key_speed) / scale);
}

std::vector<Real> view_weights(const Vec3List& key_directions, const std::vector<Real>& influences, const Vec3& view) {
  if (key_directions.size() != influences.size()) {
    throw std::invalid_argument("key_directions and influences must have the same length");
  }
  const Real view_norm = view.norm();
  if (!(view_norm > 1e-12)) throw std::invalid_argument("view must be a non-zero direction");
  const Vec3 d = view / view_norm;
  std::vector<Real> similarities;
  similarities.reserve(key_directions.size());
  for (const Vec3& key : key_directions) {
    const Real key_norm = key.norm();
    if (!(key_norm > 1e-12)) throw std::invalid_argument("key_directions must be non-zero");
    similarities.push_back(view_similarity(key / key_norm, d));
  }
  return condition_weights(similarities, influences);
}

}  // namespace kodawari::rod
