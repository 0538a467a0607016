// A CSV record of a control session, one row a sample (issue 5's log format):
//   t,seg,q1..qN,qm1..qmN,x,y,z,ax,ay,az
// time (s), motion segment index, commanded joints, measured joints (rad or m), and the
// commanded tool position (m) and approach vector computed from the commanded joints by the
// robot's forward kinematics. The communication task pushes fixed-size rows into a lock-free
// queue; a writer thread does the kinematics and the file I/O, so the sample loop never waits
// on a disk. Rows the writer cannot keep up with are dropped and counted, never blocked on.
#pragma once

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <thread>

#include "rccx/kinematics/kinematics.hpp"

namespace rccx::rtc {

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

class SampleLog {
 public:
  /// Opens (truncates) `file` and writes the header; throws LogError saying why it cannot.
  SampleLog(const std::filesystem::path& file, const kin::RobotModel& model);
  /// The log the environment asks for (RCCX_LOG=FILE), or nullptr.
  static std::unique_ptr<SampleLog> from_environment(const kin::RobotModel& model);
  /// Writes what is queued and closes the file.
  ~SampleLog();
  SampleLog(const SampleLog&) = delete;
  SampleLog& operator=(const SampleLog&) = delete;

  /// Sample loop: queues a row; false (and counted) when the queue is full.
  bool push(const LogRow& row) noexcept;
  [[nodiscard]] std::uint64_t rows_written() const noexcept { return written_.load(); }
  [[nodiscard]] std::uint64_t rows_dropped() const noexcept { return dropped_.load(); }
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }

 private:
  void write_loop();
  void write(const LogRow& row);

  static constexpr std::size_t kQueue = 4096;  ///< 4 s at 1 kHz before rows are dropped
  std::filesystem::path path_;
  std::unique_ptr<kin::Kinematics> kinematics_;
  std::FILE* file_ = nullptr;
  boost::lockfree::spsc_queue<LogRow, boost::lockfree::capacity<kQueue>> queue_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::thread writer_;
};

}  // namespace rccx::rtc
