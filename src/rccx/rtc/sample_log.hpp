// A CSV record of a control session, one row a sample (issue 5's log format), after a header
// line that says whose it is (issue 24, LogHeader below):
//   # rccx-log 1 robot=puma560 kinematics=5c1e0f2a9b3d4e67 name=puma period_ns=10000000 ...
//   t,seg,q1..qN,qm1..qmN,x,y,z,ax,ay,az
// time (s), motion segment index, commanded joints, measured joints (rad or m), and the
// commanded tool position (m) and approach vector computed from the commanded joints by the
// robot's forward kinematics. The communication task pushes fixed-size rows into a lock-free
// queue; a writer thread does the kinematics and the file I/O, so the sample loop never waits
// on a disk. In real time, rows the writer cannot keep up with are dropped and counted, never
// blocked on; in simulated time the loop waits for the writer instead (nothing is dropped).
//
// The file is written whole or not at all (rccx::io::AtomicFile): rows go to a temporary file
// beside it, in whole rows, and close() renames it over the target. A write that fails (a full
// disk) or rows dropped are said on stderr at once, and close() returns the problem so that the
// program's exit code can say the log is not complete; the target is then left as it was.
#pragma once

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "rccx/io/file.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rtc/types.hpp"

namespace rccx::rtc {

/// The log's columns for a robot of `dof` joints, in order: t, seg, q1..qN (commanded),
/// qm1..qmN (measured), x, y, z, ax, ay, az (the tool's position and approach vector). What the
/// header says and what readers of the log (rccx view --log, rccx plot) expect.
std::vector<std::string> sample_log_columns(std::size_t dof);

/// A log file that cannot be used.
class LogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Whose a log is: its first line, before the column line, so that a reader (rccx plot, rccx view
/// --log) draws it as its own robot and refuses another:
///   # rccx-log 1 robot=puma560 kinematics=5c1e0f2a9b3d4e67 name=left period_ns=10000000
///     clock=simulated rccx=0.1.0                                  (one line)
/// `1` is the format's version; then key=value words, in this order (a reader ignores keys it
/// does not know). A value has no space: a space is written %20, a % %25.
struct LogHeader {
  std::string robot;           ///< the robot file's "name" (a shipped robot's: `rccx kin robots`)
  std::string kinematics;      ///< kinematics_fingerprint() of the robot, 16 hex digits
  std::string name;            ///< the robot's name in its cell (its model's name when alone)
  std::int64_t period_ns = 0;  ///< the robot's sample period, ns
  bool simulated = true;       ///< clock=simulated or clock=realtime
  std::string rccx;            ///< the version of rccx that wrote it

  /// The header of `model`'s log, named `name` (empty: the model's name), the running rccx.
  static LogHeader of(const kin::RobotModel& model, std::string_view name,
                      std::chrono::nanoseconds period, bool simulated);
  /// The line, with its newline.
  [[nodiscard]] std::string line() const;
  /// The header of a line that starts "# rccx-log", else nullopt. Throws LogError for such a
  /// line that is not a whole header (says what is missing or wrong).
  static std::optional<LogHeader> parse(std::string_view line);
};

/// 16 hex digits that tell one robot's geometry from another's (a 64-bit FNV-1a hash of each
/// joint's type and DH parameters): a robot file that shares a shipped robot's name but not its
/// geometry has another fingerprint.
std::string kinematics_fingerprint(const kin::RobotModel& model);

struct LogRow {
  double t_s = 0.0;
  std::int32_t segment = 0;
  kin::JointVector commanded;  ///< rad or m
  kin::JointVector measured;   ///< rad or m
};

/// A second consumer of the controlled samples, beside the log: what rccx::view taps the loop
/// with. The communication task calls on_sample once a controlled sample, after the Chg was
/// applied, with the How it read and the joints it commanded (rad / m; the measured value for a
/// joint not commanded yet). It must return at once: no lock, no allocation, no exception (push
/// into a lock-free buffer and return, as SampleLog::push does).
class SampleTap {
 public:
  virtual ~SampleTap() = default;
  virtual void on_sample(const How& how, const kin::JointVector& commanded,
                         std::int32_t segment) noexcept = 0;
};

class SampleLog {
 public:
  /// Starts the log of `file` (written when closed) with `header` and the column line; throws
  /// LogError saying why it cannot (a directory, a missing directory, no permission).
  SampleLog(const std::filesystem::path& file, const kin::RobotModel& model,
            const LogHeader& header);
  /// The log the environment asks for (RCCX_LOG=FILE), or nullptr; its errors name RCCX_LOG.
  /// `suffix` is for one robot of several: RCCX_LOG=cell.csv gives cell<suffix>.csv.
  static std::unique_ptr<SampleLog> from_environment(const kin::RobotModel& model,
                                                     const LogHeader& header,
                                                     std::string_view suffix = {});
  /// Writes what is queued and puts the file in place. Empty when the log is complete, else
  /// what went wrong (rows dropped, a write that failed: the target is then left as it was).
  /// Only the first call does anything.
  std::string close();
  /// close(), its problem already said on stderr.
  ~SampleLog();
  SampleLog(const SampleLog&) = delete;
  SampleLog& operator=(const SampleLog&) = delete;

  /// Sample loop: queues a row; false (and counted) when the queue is full. With
  /// `wait_for_room` (simulated time, where no deadline waits on the loop) it yields until the
  /// writer has made room instead: a fast simulated run is slowed to the writer's pace, its log
  /// never loses a row.
  bool push(const LogRow& row, bool wait_for_room = false) noexcept;
  [[nodiscard]] std::uint64_t rows_written() const noexcept { return written_.load(); }
  [[nodiscard]] std::uint64_t rows_dropped() const noexcept { return dropped_.load(); }
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }

 private:
  void write_loop(std::string pending);
  void format(const LogRow& row, std::string& out);
  void flush(std::string& pending);

  std::string name_;  ///< how messages name the log: "--log F" or "RCCX_LOG F"
  static constexpr std::size_t kQueue = 4096;  ///< 4 s at 1 kHz before rows are dropped
  std::filesystem::path path_;
  std::unique_ptr<kin::Kinematics> kinematics_;
  std::unique_ptr<io::AtomicFile> file_;
  std::string error_;  ///< writer thread's, read after it is joined
  bool closed_ = false;
  boost::lockfree::spsc_queue<LogRow, boost::lockfree::capacity<kQueue>> queue_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::thread writer_;
};

}  // namespace rccx::rtc
