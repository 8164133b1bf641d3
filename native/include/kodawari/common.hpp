// The one math vocabulary of the core: every solver speaks Eigen through these names.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

namespace kodawari {

using Real = double;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Vec3f = Eigen::Matrix<float, 3, 1>;
using Quat = Eigen::Quaternion<Real>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Vec3List = std::vector<Vec3, Eigen::aligned_allocator<Vec3>>;
using QuatList = std::vector<Quat, Eigen::aligned_allocator<Quat>>;

constexpr Real kPi = Real(3.14159265358979323846);

inline Real degrees_to_radians(Real degrees) { return degrees * kPi / Real(180); }
inline Real radians_to_degrees(Real radians) { return radians * Real(180) / kPi; }

}  // namespace kodawari
