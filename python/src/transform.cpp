#include "transform.hpp"

#include <fmt/format.h>

namespace rccx::python {

std::optional<math::Transform> homogeneous(const InArray& a, std::string& why) {
  if (ndim(a) != 2 || extent(a, 0) != 4 || extent(a, 1) != 4) {
    why = fmt::format("T must be a (4, 4) homogeneous transform (m), got shape {}", shape_text(a));
    return std::nullopt;
  }
  const double* m = a.data();
  if (!all_finite(m, 16)) {
    why = "T has a non-finite element";
    return std::nullopt;
  }
  if (m[12] != 0.0 || m[13] != 0.0 || m[14] != 0.0 || m[15] != 1.0) {
    why = fmt::format("T's last row must be 0 0 0 1, got {} {} {} {}", m[12], m[13], m[14], m[15]);
    return std::nullopt;
  }
  return math::Transform::from_rows(
      {m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9], m[10], m[11]});
}

math::Transform transform_in(const InArray& a, const std::string& what) {
  std::string why;
  const std::optional<math::Transform> T = homogeneous(a, why);
  if (!T) raise_value_error(fmt::format("{}: {}", what, why));
  const math::Rot3 RtR = T->R.transposed() * T->R;
  double error = 0.0;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) error = std::max(error, std::abs(RtR(r, c) - (r == c ? 1.0 : 0.0)));
  }
  const double det = math::dot(math::cross(T->R.n, T->R.o), T->R.a);
  if (error > 1e-6 || det < 0) {
    raise_value_error(fmt::format(
        "{}: T's rotation part is not a rotation matrix (|RtR - I| = {:.2g}, det = {:.6g}); give "
        "an orthonormal, right-handed frame (within 1e-6)",
        what, error, det));
  }
  return *T;
}

}  // namespace rccx::python
