#pragma once
// Basic numeric types shared by every layer.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

// Forced inline into the hot loops: called out of line, a result struct went through the stack and
// was read back with wider loads than it was written with (store-forwarding stalls were the hottest
// samples of the contact loop in the profile), and g++'s inliner gives up on the slots and kernels
// once a loop has grown (the vectorised path beside the scalar one). Inlining changes no result.
#if defined(__GNUC__)
#define GRAINLAB_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define GRAINLAB_ALWAYS_INLINE inline
#endif

namespace grainlab {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

constexpr double kPi = 3.14159265358979323846;
inline double degToRad(double d) { return d * kPi / 180.0; }
inline double radToDeg(double r) { return r * 180.0 / kPi; }

}  // namespace grainlab
