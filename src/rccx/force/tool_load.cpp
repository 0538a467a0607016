#include "rccx/force/tool_load.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace rccx::force {

math::Wrench external_wrench(const ToolLoad& load, const math::Rot3& world_from_sensor,
                             const math::Wrench& reading) noexcept {
  const math::Wrench weight =
      math::weight_wrench(world_from_sensor, load.mass_kg, load.com_m, kGravity_m_per_s2);
  return reading - load.bias - weight;
}

math::Wrench at_tool(const math::Transform& t6_from_tool, const math::Wrench& at_t6) noexcept {
  return math::transform_wrench(t6_from_tool.inverse(), at_t6);
}

namespace {

constexpr const char* kWhatToDo =
    "take readings at three or more orientations that differ about two axes (gravity must point "
    "in three or more directions in the sensor frame)";

bool finite(const math::Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

ToolLoad estimate_tool_load(std::span<const LoadSample> samples, LoadFit* fit) {
  const std::size_t n = samples.size();
  if (n < 3) {
    throw std::invalid_argument(fmt::format(
        "tool load: {} reading{} cannot determine the bias, mass and centre of mass; {}", n,
        n == 1 ? "" : "s", kWhatToDo));
  }
  // Unknowns, all in N or N m so that the columns are alike: b_f (3), b_t (3), w = m g, and
  // h = m g c (3). With u = R^T (0, 0, -1), gravity's direction in the sensor frame:
  //   force = b_f + w u,   torque = b_t + h x u = b_t - [u]x h.
  const auto rows = static_cast<Eigen::Index>(6 * n);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, 10);
  Eigen::VectorXd b(rows);
  for (std::size_t i = 0; i < n; ++i) {
    const LoadSample& s = samples[i];
    const math::Rot3& R = s.world_from_sensor;
    if (!finite(R.n) || !finite(R.o) || !finite(R.a) || !finite(s.reading.force_N) ||
        !finite(s.reading.torque_N_m)) {
      throw std::invalid_argument(
          fmt::format("tool load: reading {} has a non-finite orientation or wrench", i + 1));
    }
    const math::Vec3 u = R.transpose_times({0.0, 0.0, -1.0});
    const auto r = static_cast<Eigen::Index>(6 * i);
    A.block<3, 3>(r, 0).setIdentity();
    A(r + 0, 6) = u.x;
    A(r + 1, 6) = u.y;
    A(r + 2, 6) = u.z;
    A.block<3, 3>(r + 3, 3).setIdentity();
    // -[u]x
    A(r + 3, 8) = u.z;
    A(r + 3, 9) = -u.y;
    A(r + 4, 7) = -u.z;
    A(r + 4, 9) = u.x;
    A(r + 5, 7) = u.y;
    A(r + 5, 8) = -u.x;
    const auto w = s.reading.to_array();
    for (int k = 0; k < 6; ++k) b(r + k) = w[static_cast<std::size_t>(k)];
  }

  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  const double conditioning = sv(0) > 0.0 ? sv(sv.size() - 1) / sv(0) : 0.0;
  if (!(conditioning >= kMinLoadConditioning)) {
    throw std::invalid_argument(fmt::format(
        "tool load: the {} readings do not determine the bias, mass and centre of mass (their "
        "orientations are too alike: conditioning {:.2g}, at least {:.2g} needed); {}",
        n, conditioning, kMinLoadConditioning, kWhatToDo));
  }
  const Eigen::VectorXd x = svd.solve(b);

  ToolLoad load;
  load.bias = {{x(0), x(1), x(2)}, {x(3), x(4), x(5)}};
  const double weight_N = x(6);
  load.mass_kg = weight_N / kGravity_m_per_s2;
  if (weight_N != 0.0) load.com_m = math::Vec3{x(7), x(8), x(9)} / weight_N;

  if (fit != nullptr) {
    const Eigen::VectorXd residual = A * x - b;
    double force_sq = 0.0, torque_sq = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto r = static_cast<Eigen::Index>(6 * i);
      force_sq += residual.segment<3>(r).squaredNorm();
      torque_sq += residual.segment<3>(r + 3).squaredNorm();
    }
    const auto axes = static_cast<double>(3 * n);
    fit->samples = n;
    fit->rms_force_N = std::sqrt(force_sq / axes);
    fit->rms_torque_N_m = std::sqrt(torque_sq / axes);
    fit->conditioning = conditioning;
  }
  return load;
}

}  // namespace rccx::force
