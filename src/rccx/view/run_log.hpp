// A run recorded by rtc::SampleLog (`--log FILE`, RCCX_LOG), read back for `rccx view --log`
// (the replay) and `rccx plot`. The file must be exactly what SampleLog writes:
//   t,seg,q1..qN,qm1..qmN,x,y,z,ax,ay,az
// anything else is refused with the line and the column that is wrong.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/kinematics/joint_vector.hpp"

namespace rccx::view {

/// A file that is not a SampleLog CSV: the message names the file, the line and the column.
class RunLogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct RunRow {
  double t_s = 0.0;
  std::int32_t segment = 0;
  kin::JointVector commanded;  ///< rad or m
  kin::JointVector measured;   ///< rad or m
  double p[3]{};               ///< commanded tool position in the robot's base frame, m
  double a[3]{};               ///< commanded approach vector
};

struct RunLog {
  std::size_t dof = 0;
  std::vector<RunRow> rows;
};

/// Parses the text of a log; `origin` names it in errors. At least one row; times increase.
RunLog parse_run_log(std::string_view text, std::string_view origin);
/// Reads and parses a log file (RunLogError when it cannot be read).
RunLog load_run_log(const std::filesystem::path& file);

}  // namespace rccx::view
