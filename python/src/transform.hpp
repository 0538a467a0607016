// NumPy (4, 4) arrays to and from math::Transform, checked once for every binding (rccx.kin,
// the equations, the robots, the position database): the shape, finite elements, the last row
// 0 0 0 1 and, where a frame is meant, a rotation part orthonormal and right-handed.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>

#include "arrays.hpp"
#include "rccx/math/transform.hpp"

namespace rccx::python {

inline bool all_finite(const double* v, std::size_t n) {
  return std::all_of(v, v + n, [](double x) { return std::isfinite(x); });
}

/// The array as a transform when it is (4, 4), finite and its last row is 0 0 0 1; otherwise
/// nullopt and `why` says what is wrong ("T must be a (4, 4) ..."). The rotation is not judged.
std::optional<math::Transform> homogeneous(const InArray& a, std::string& why);

/// A (4, 4) homogeneous transform (m) from Python: homogeneous(), and its rotation part
/// orthonormal and right-handed within 1e-6 as `rccx kin ik --T` requires; ValueError naming
/// `what` otherwise.
math::Transform transform_in(const InArray& a, const std::string& what);

/// T written row by row into 16 doubles.
inline void write_transform(const math::Transform& T, double* out) {
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) *out++ = T(r, c);
  }
}
/// T as a new (4, 4) float64 array.
inline OutArray transform_out(const math::Transform& T) {
  OutArray out = new_array({4, 4});
  write_transform(T, out.mutable_data());
  return out;
}

}  // namespace rccx::python
