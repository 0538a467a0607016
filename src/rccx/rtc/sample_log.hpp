// A CSV record of a control session, one row a sample (issue 5's log format):
//   t,seg,q1..qN,qm1..qmN,x,y,z,ax,ay,az
// time (s), motion segment index, commanded joints, measured joints (rad or m), and the
// commanded tool position (m) and approach vector computed from the commanded joints by the
// robot's forward kinematics. The communication task pushes fixed-size rows into a lock-free
// queue; a writer thread does the kinematics and the file I/O, so the sample loop never waits
// on a disk. Rows the writer cannot keep up with are dropped and counted, never blocked on.
//
// The file is written whole or not at all (rccx::io::AtomicFile): rows go to a temporary file
// beside it, in whole rows, and close() renames it over the target. A write that fails (a full
// disk) or rows dropped are said on stderr at once, and close() returns the problem so that the
// program's exit code can say the log is not complete; the target is then left as it was.
#pragma once

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

#include <string>

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
  /// Starts the log of `file` (written when closed) with its header; throws LogError saying
  /// why it cannot (a directory, a missing directory, no permission).
  SampleLog(const std::filesystem::path& file, const kin::RobotModel& model);
  /// The log the environment asks for (RCCX_LOG=FILE), or nullptr; its errors name RCCX_LOG.
  static std::unique_ptr<SampleLog> from_environment(const kin::RobotModel& model);
  /// The same for one robot of several: RCCX_LOG=cell.csv gives cell<suffix>.csv.
  static std::unique_ptr<SampleLog> from_environment(const kin::RobotModel& model,
                                                     std::string_view suffix);
  /// Writes what is queued and puts the file in place. Empty when the log is complete, else
  /// what went wrong (rows dropped, a write that failed: the target is then left as it was).
  /// Only the first call does anything.
  std::string close();
  /// close(), its problem already said on stderr.
  ~SampleLog();
  SampleLog(const SampleLog&) = delete;
  SampleLog& operator=(const SampleLog&) = delete;

  /// Sample loop: queues a row; false (and counted) when the queue is full.
  bool push(const LogRow& row) noexcept;
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
