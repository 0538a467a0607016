// Checks of commanded joint paths recorded from RobotState samples, shared by the serve tests
// (loopback) and the hosts tests (network namespaces).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"

namespace rccx::test {

/// The largest |second difference| / P^2 over the bound, any joint, over consecutive samples
/// from index `from` on: 1 means at the bound. `Record` has `sample`, `period_s` (s) and `q`.
template <class Record>
double worst_acceleration_ratio(const std::vector<Record>& v, std::size_t from,
                                const kin::JointVector& bound) {
  double worst = 0.0;
  for (std::size_t i = std::max<std::size_t>(from, 2); i < v.size(); ++i) {
    if (v[i].sample != v[i - 1].sample + 1 || v[i - 1].sample != v[i - 2].sample + 1) continue;
    const double P = v[i].period_s;
    for (std::size_t j = 0; j < v[i].q.size(); ++j) {
      const double a = (v[i].q[j] - 2 * v[i - 1].q[j] + v[i - 2].q[j]) / (P * P);
      worst = std::max(worst, std::abs(a) / bound[j]);
    }
  }
  return worst;
}

}  // namespace rccx::test
