#include "kodawari/rod/shape_blend.hpp"

#include <stdexcept>

namespace kodawari::rod {

QuatList blend_shapes(const std::vector<QuatList>& key_shapes, const std::vector<Real>& weights,
                      std::size_t bone_count) {
  if (weights.size() != key_shapes.size() + 1) throw std::invalid_argument("need one weight per key plus the base");
  std::vector<const QuatList*> shapes;
  shapes.reserve(key_shapes.size());
  for (const QuatList& shape : key_shapes) shapes.push_back(&shape);
  QuatList out;
  blend_shapes_into(shapes.data(), shapes.size(), weights.data(), bone_count, out);
  return out;
}

void blend_shapes_into(const QuatList* const* key_shapes, std::size_t key_count, const Real* weights,
                       std::size_t bone_count, QuatList& out) {
  out.resize(bone_count);
  for (std::size_t k = 0; k < bone_count; ++k) {
    // Base shape: the identity (the bones' rest pose), weight w[0].
    Eigen::Matrix<Real, 4, 1> sum(weights[0], 0, 0, 0);  // (w, x, y, z)
    for (std::size_t i = 0; i < key_count; ++i) {
      const Quat& q = (*key_shapes[i])[k];
      const Real sign = q.w() < 0 ? Real(-1) : Real(1);
      sum += weights[i + 1] * sign * Eigen::Matrix<Real, 4, 1>(q.w(), q.x(), q.y(), q.z());
    }
    const Real norm = sum.norm();
    out[k] = norm > 1e-12 ? Quat(sum[0] / norm, sum[1] / norm, sum[2] / norm, sum[3] / norm) : Quat::Identity();
  }
}

void chain_forward_kinematics(const ChainGeometry& geometry, const QuatList& local_rotations, QuatList& frames,
                              Vec3List& heads) {
  const std::size_t n = geometry.bone_count();
  frames.resize(n);
  heads.resize(n + 1);
  // The anchor frame is bone 0's rest frame under the posed parent: its head is the origin.
  heads[0] = Vec3::Zero();
  frames[0] = local_rotations[0];
  for (std::size_t k = 1; k < n; ++k) {
    heads[k] = heads[k - 1] + frames[k - 1] * geometry.offsets[k];
    frames[k] = (frames[k - 1] * geometry.rest_rotations[k] * local_rotations[k]).normalized();
  }
  heads[n] = heads[n - 1] + frames[n - 1] * geometry.offsets[n];
}

}  // namespace kodawari::rod
