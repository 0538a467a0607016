#include "rccx/rtc/sample_log.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>

namespace rccx::rtc {

SampleLog::SampleLog(const std::filesystem::path& file, const kin::RobotModel& model)
    : path_(file), kinematics_(kin::make_kinematics(model)) {
  file_ = std::fopen(file.c_str(), "w");
  if (file_ == nullptr) {
    throw LogError(fmt::format("cannot write the log {}: {}", file.string(), std::strerror(errno)));
  }
  const std::size_t n = model.dof();
  std::string header = "t,seg";
  for (std::size_t i = 1; i <= n; ++i) header += fmt::format(",q{}", i);
  for (std::size_t i = 1; i <= n; ++i) header += fmt::format(",qm{}", i);
  header += ",x,y,z,ax,ay,az\n";
  std::fputs(header.c_str(), file_);
  writer_ = std::thread([this] { write_loop(); });
}

std::unique_ptr<SampleLog> SampleLog::from_environment(const kin::RobotModel& model) {
  const char* file = std::getenv("RCCX_LOG");
  if (file == nullptr || *file == '\0') return nullptr;
  return std::make_unique<SampleLog>(file, model);
}

SampleLog::~SampleLog() {
  stop_ = true;
  writer_.join();
  std::fclose(file_);
}

bool SampleLog::push(const LogRow& row) noexcept {
  if (queue_.push(row)) return true;
  dropped_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

void SampleLog::write_loop() {
  // Drains every few milliseconds: the file sees whole batches, the loop never waits for it.
  for (;;) {
    const bool stopping = stop_.load();
    LogRow row;
    while (queue_.pop(row)) write(row);
    if (stopping) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::fflush(file_);
}

void SampleLog::write(const LogRow& row) {
  fmt::memory_buffer line;
  fmt::format_to(std::back_inserter(line), "{:.6f},{}", row.t_s, row.segment);
  for (double q : row.commanded) fmt::format_to(std::back_inserter(line), ",{:.9g}", q);
  for (double q : row.measured) fmt::format_to(std::back_inserter(line), ",{:.9g}", q);
  const math::Transform T = kinematics_->forward(row.commanded);
  fmt::format_to(std::back_inserter(line), ",{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", T.p.x,
                 T.p.y, T.p.z, T.R.a.x, T.R.a.y, T.R.a.z);
  std::fwrite(line.data(), 1, line.size(), file_);
  written_.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace rccx::rtc
