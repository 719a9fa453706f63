// Math vocabulary of Sylva: Eigen 3.4 types under short names.
// Geometry is double precision; the world is Y-up and right-handed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sylva {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Vec3f = Eigen::Vector3f;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

}  // namespace sylva
