// A joint vector of up to kMaxJoints values (rad for revolute joints, m for prismatic ones),
// held by value so that the sample loop can pass and return it without touching the heap.
//
//   kin::JointVector q{0.0, 45_deg, -180_deg, 0.0, 45_deg, 0.0};   // the PUMA's ready pose, rad
//   kin::JointVector v(model.dof());                                  // dof() zeros
//   q[1] += 5_deg;
//   for (double& x : v) x = 0.1;                                      // rad/s, say
//   std::span<const double> values = q.span();                        // q.size() of them
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>

namespace rccx::kin {

inline constexpr std::size_t kMaxJoints = 8;

class JointVector {
 public:
  constexpr JointVector() noexcept = default;
  /// n zeros.
  constexpr explicit JointVector(std::size_t n) noexcept : n_(static_cast<std::uint8_t>(n)) {
    assert(n <= kMaxJoints);
  }
  constexpr JointVector(std::initializer_list<double> values) noexcept
      : n_(static_cast<std::uint8_t>(values.size())) {
    assert(values.size() <= kMaxJoints);
    std::copy(values.begin(), values.end(), v_.begin());
  }
  constexpr explicit JointVector(std::span<const double> values) noexcept
      : n_(static_cast<std::uint8_t>(values.size())) {
    assert(values.size() <= kMaxJoints);
    std::copy(values.begin(), values.end(), v_.begin());
  }

  [[nodiscard]] constexpr std::size_t size() const noexcept { return n_; }
  [[nodiscard]] constexpr bool empty() const noexcept { return n_ == 0; }
  constexpr double& operator[](std::size_t i) noexcept { return v_[i]; }
  constexpr double operator[](std::size_t i) const noexcept { return v_[i]; }
  [[nodiscard]] constexpr double* data() noexcept { return v_.data(); }
  [[nodiscard]] constexpr const double* data() const noexcept { return v_.data(); }
  constexpr double* begin() noexcept { return v_.data(); }
  constexpr double* end() noexcept { return v_.data() + n_; }
  [[nodiscard]] constexpr const double* begin() const noexcept { return v_.data(); }
  [[nodiscard]] constexpr const double* end() const noexcept { return v_.data() + n_; }
  [[nodiscard]] constexpr std::span<const double> span() const noexcept { return {v_.data(), n_}; }

  constexpr bool operator==(const JointVector& b) const noexcept {
    return n_ == b.n_ && std::equal(begin(), end(), b.begin());
  }

 private:
  std::array<double, kMaxJoints> v_{};
  std::uint8_t n_ = 0;
};

}  // namespace rccx::kin
