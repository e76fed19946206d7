#pragma once
// Basic numeric types shared by every layer.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace grainlab {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

constexpr double kPi = 3.14159265358979323846;
inline double degToRad(double d) { return d * kPi / 180.0; }
inline double radToDeg(double r) { return r * 180.0 / kPi; }

}  // namespace grainlab
