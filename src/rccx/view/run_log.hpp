// A run recorded by rtc::SampleLog (`--log FILE`, RCCX_LOG), read back for `rccx view --log`
// (the replay) and `rccx plot`. The file must be exactly what SampleLog writes:
//   # rccx-log 1 robot=... kinematics=... name=... period_ns=... clock=... rccx=...
//   t,seg,q1..qN,qm1..qmN,x,y,z,ax,ay,az
// anything else is refused with the line and the column that is wrong. The header line says
// whose the log is (rtc::LogHeader); log_robot() draws it as that robot and refuses another. A
// log of rccx 0.1.0 before the header has none: it is read as the robot the user names.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/kinematics/joint_vector.hpp"
#include "rccx/kinematics/robot_model.hpp"
#include "rccx/rtc/sample_log.hpp"

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
  std::string origin;                    ///< the file, for messages
  std::optional<rtc::LogHeader> header;  ///< none in a log written before headers
  std::size_t dof = 0;
  std::vector<RunRow> rows;
};

/// Parses the text of a log; `origin` names it in errors. At least one row; times increase.
RunLog parse_run_log(std::string_view text, std::string_view origin);
/// Reads and parses a log file (RunLogError when it cannot be read).
RunLog load_run_log(const std::filesystem::path& file);

/// The robot `log` is drawn as. `given`: the robot the user named (null: none), `given_as`
/// how (`--robot puma560`, `--robot-file arm.json`) for messages. With a header: the robot it
/// names (a shipped robot whose kinematics match it, else `given`), and RunLogError when
/// `given` is another robot (another name or another geometry) or when it names a robot file
/// and none is given. Without a header (an old log): `given`, and RunLogError when none is.
kin::RobotModel log_robot(const RunLog& log, const kin::RobotModel* given,
                          std::string_view given_as);

}  // namespace rccx::view
