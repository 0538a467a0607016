#include "rccx/view/run_log.hpp"

#include <fmt/format.h>

#include "rccx/io/file.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/rtc/sample_log.hpp"

namespace rccx::view {

namespace {

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(
        line.substr(start, comma == std::string_view::npos ? line.npos : comma - start));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

constexpr std::string_view kExpected =
    "a log rccx writes (--log FILE or RCCX_LOG=FILE): t,seg,q1..qN,qm1..qmN,x,y,z,ax,ay,az";

}  // namespace

RunLog parse_run_log(std::string_view text, std::string_view origin) {
  RunLog log;
  log.origin = origin;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  std::size_t column_line = 1;  // after the comment lines at the top
  std::vector<std::string> header;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line_no == column_line && line.starts_with('#')) {
      ++column_line;
      try {
        if (auto h = rtc::LogHeader::parse(line); h && !log.header) log.header = std::move(h);
      } catch (const rtc::LogError& e) {
        throw RunLogError(fmt::format("{}:{}: {}", origin, line_no, e.what()));
      }
      continue;
    }
    const auto cells = split(line);
    if (line_no == column_line) {
      if (!io::is_utf8(line) || cells.size() < 2 + 2 + 6 || cells[0] != "t" || cells[1] != "seg" ||
          (cells.size() - 8) % 2 != 0) {
        throw RunLogError(fmt::format("{}:{}: the header {} is not {}", origin, line_no,
                                      io::quoted(line.substr(0, 80)), kExpected));
      }
      log.dof = (cells.size() - 8) / 2;
      if (log.dof > kin::kMaxJoints) {
        throw RunLogError(fmt::format("{}:{}: {} joints; rccx logs at most {}", origin, line_no,
                                      log.dof, kin::kMaxJoints));
      }
      header = rtc::sample_log_columns(log.dof);         // the columns rtc::SampleLog writes
      header.erase(header.begin(), header.begin() + 2);  // t and seg, checked above
      for (std::size_t i = 0; i < header.size(); ++i) {
        if (cells[i + 2] != header[i]) {
          throw RunLogError(fmt::format("{}:{}: column {} is {}, expected {}: not {}", origin,
                                        line_no, i + 3, io::quoted(cells[i + 2].substr(0, 40)),
                                        header[i], kExpected));
        }
      }
      continue;
    }
    if (line.empty() && pos >= text.size()) break;  // the final newline
    if (cells.size() != header.size() + 2) {
      throw RunLogError(fmt::format("{}:{}: {} columns, the header has {}", origin, line_no,
                                    cells.size(), header.size() + 2));
    }
    RunRow row;
    const auto number = [&](std::size_t column, std::string_view name) {
      try {
        return io::parse_number(cells[column], name);
      } catch (const io::ParseError& e) {
        throw RunLogError(
            fmt::format("{}:{}: column {} ({}): {}", origin, line_no, column + 1, name, e.what()));
      }
    };
    row.t_s = number(0, "t");
    try {
      row.segment = static_cast<std::int32_t>(io::parse_integer(cells[1], "seg", 0, INT32_MAX));
    } catch (const io::ParseError& e) {
      throw RunLogError(fmt::format("{}:{}: column 2 (seg): {}", origin, line_no, e.what()));
    }
    row.commanded = kin::JointVector(log.dof);
    row.measured = kin::JointVector(log.dof);
    for (std::size_t i = 0; i < log.dof; ++i) {
      row.commanded[i] = number(2 + i, header[i]);
      row.measured[i] = number(2 + log.dof + i, header[log.dof + i]);
    }
    for (std::size_t k = 0; k < 3; ++k) {
      row.p[k] = number(2 + 2 * log.dof + k, header[2 * log.dof + k]);
      row.a[k] = number(5 + 2 * log.dof + k, header[2 * log.dof + 3 + k]);
    }
    if (!log.rows.empty() && row.t_s <= log.rows.back().t_s) {
      throw RunLogError(fmt::format("{}:{}: column 1 (t): time {} does not follow {}", origin,
                                    line_no, row.t_s, log.rows.back().t_s));
    }
    log.rows.push_back(row);
  }
  if (line_no == 0) throw RunLogError(fmt::format("{}: empty: not {}", origin, kExpected));
  if (log.rows.empty()) throw RunLogError(fmt::format("{}: a header and no samples", origin));
  return log;
}

RunLog load_run_log(const std::filesystem::path& file) {
  std::string text;
  try {
    text = io::read_file(file);
  } catch (const std::exception& e) {
    throw RunLogError(fmt::format("cannot read the log: {}", e.what()));
  }
  return parse_run_log(text, file.string());
}

namespace {

/// The shipped robot of that name and geometry, if there is one.
std::optional<kin::RobotModel> shipped(const rtc::LogHeader& h) {
  for (const std::string& name : kin::builtin_robot_names()) {
    if (name != h.robot) continue;
    kin::RobotModel m = kin::builtin_robot(name);
    if (rtc::kinematics_fingerprint(m) == h.kinematics) return m;
  }
  return std::nullopt;
}

}  // namespace

kin::RobotModel log_robot(const RunLog& log, const kin::RobotModel* given,
                          std::string_view given_as) {
  if (!log.header) {
    if (given != nullptr) return *given;
    throw RunLogError(fmt::format(
        "{}: the log has no header line naming its robot (written by rccx before 0.1.0's "
        "headers, or not by rccx): say which robot it is with --robot NAME or --robot-file FILE",
        log.origin));
  }
  const rtc::LogHeader& h = *log.header;
  const std::string whose =
      fmt::format("{} is a log of robot {} (named {} in its run, kinematics {})", log.origin,
                  h.robot, h.name, h.kinematics);
  if (given != nullptr) {
    if (given->name == h.robot && rtc::kinematics_fingerprint(*given) == h.kinematics) {
      return *given;
    }
    throw RunLogError(fmt::format(
        "{}, not of {} (robot {}, kinematics {}): leave {} out to draw it as its own robot, or "
        "give the robot file it was recorded with",
        whose, given_as, given->name, rtc::kinematics_fingerprint(*given), given_as));
  }
  if (std::optional<kin::RobotModel> m = shipped(h)) return *m;
  throw RunLogError(fmt::format(
      "{}, which is no shipped robot (`rccx kin robots`): give its robot file with --robot-file "
      "FILE",
      whose));
}

}  // namespace rccx::view
