#pragma once
/// \file
/// \brief Seeded random inputs for property tests: every run of a test sees the same numbers.

#include <cmath>
#include <cstdint>
#include <random>

#include "grbd/core/types.hpp"
#include "grbd/kinematics/quaternion.hpp"
#include "grbd/kinematics/rotation.hpp"

namespace grbd::test {

/// A seeded source of random test inputs.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}

  /// Uniform in [lo, hi).
  double uniform(double lo = -1.0, double hi = 1.0) {
    return std::uniform_real_distribution<double>(lo, hi)(engine_);
  }
  /// Each coordinate uniform in [lo, hi).
  Vector3 vector3(double lo = -1.0, double hi = 1.0) {
    return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
  }
  /// A unit vector, uniform on the sphere S².
  Vector3 unit_vector3() {
    std::normal_distribution<double> n;
    Vector3 v(n(engine_), n(engine_), n(engine_));
    return v.normalized();
  }
  /// A quaternion with each coordinate uniform in [lo, hi).
  kinematics::Quaternion quaternion(double lo = -2.0, double hi = 2.0) {
    return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
  }
  /// A unit quaternion, uniform on S³ (normalised Gaussian 4-vector).
  kinematics::Quaternion unit_quaternion() {
    std::normal_distribution<double> n;
    Vector4 K(n(engine_), n(engine_), n(engine_), n(engine_));
    return kinematics::Quaternion(Vector4(K.normalized()));
  }
  /// A rotation matrix, uniform on SO(3): R(p) of a unit_quaternion().
  Matrix3 rotation() { return kinematics::rotation_matrix(unit_quaternion()); }

  std::mt19937_64& engine() { return engine_; }

 private:
  std::mt19937_64 engine_;
};

}  // namespace grbd::test
