#include "rccx/rtc/velocity_estimator.hpp"

#include <algorithm>

namespace rccx::rtc {

kin::JointVector VelocityEstimator::update(double t_s, const kin::JointVector& q) noexcept {
  history_[count_ % kHistory] = {t_s, q};
  // The newest sample at least a window old, or the oldest kept.
  const Sample* old = nullptr;
  const std::size_t kept = std::min(count_, kHistory - 1);
  for (std::size_t back = 1; back <= kept; ++back) {
    old = &history_[(count_ - back) % kHistory];
    if (t_s - old->t_s >= kWindow_s) break;
  }
  ++count_;
  kin::JointVector v(q.size());
  const double dt = old ? t_s - old->t_s : 0.0;
  if (dt <= 0.0) return v;
  for (std::size_t i = 0; i < q.size(); ++i) v[i] = (q[i] - old->q[i]) / dt;
  return v;
}

void VelocityEstimator::restart(std::size_t i, double q) noexcept {
  for (Sample& s : history_) {
    if (i < s.q.size()) s.q[i] = q;
  }
}

}  // namespace rccx::rtc
