#include "rccx/rtc/sample_log.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cstdlib>

#include "rccx/io/console.hpp"

namespace rccx::rtc {

std::vector<std::string> sample_log_columns(std::size_t dof) {
  std::vector<std::string> columns{"t", "seg"};
  for (std::size_t i = 1; i <= dof; ++i) columns.push_back(fmt::format("q{}", i));
  for (std::size_t i = 1; i <= dof; ++i) columns.push_back(fmt::format("qm{}", i));
  for (const char* c : {"x", "y", "z", "ax", "ay", "az"}) columns.emplace_back(c);
  return columns;
}

SampleLog::SampleLog(const std::filesystem::path& file, const kin::RobotModel& model)
    : name_(file.string()), path_(file), kinematics_(kin::make_kinematics(model)) {
  try {
    file_ = std::make_unique<io::AtomicFile>(file);  // refuses a directory, a missing one
  } catch (const io::FileError& e) {
    throw LogError(fmt::format("cannot write the log: {}", e.what()));
  }
  // The header goes with the first rows: a disk that is full from the start is a write that
  // fails (said at once, the log not saved), not a bad file name.
  std::string header = fmt::format("{}\n", fmt::join(sample_log_columns(model.dof()), ","));
  writer_ =
      std::thread([this, header = std::move(header)]() mutable { write_loop(std::move(header)); });
}

std::unique_ptr<SampleLog> SampleLog::from_environment(const kin::RobotModel& model) {
  return from_environment(model, {});
}

std::unique_ptr<SampleLog> SampleLog::from_environment(const kin::RobotModel& model,
                                                       std::string_view suffix) {
  const char* value = std::getenv("RCCX_LOG");
  if (value == nullptr || *value == '\0') return nullptr;
  std::filesystem::path file(value);
  if (!suffix.empty()) {
    file.replace_filename(file.stem().string() + std::string(suffix) + file.extension().string());
  }
  try {
    return std::make_unique<SampleLog>(file, model);
  } catch (const LogError& e) {
    throw LogError(fmt::format("RCCX_LOG={}: {} (unset RCCX_LOG or name a file you can write)",
                               value, e.what()));
  }
}

std::string SampleLog::close() {
  if (closed_) return {};
  closed_ = true;
  stop_.store(true);
  writer_.join();
  std::string problem = error_;
  if (problem.empty() && dropped_.load() > 0) {
    problem = fmt::format("the log {} is missing {} rows the disk could not keep up with", name_,
                          dropped_.load());
  }
  if (problem.empty()) {
    try {
      file_->commit();
    } catch (const io::FileError& e) {
      problem = fmt::format("the log was not saved: {}", e.what());
      io::eprint("rccx: {}\n", problem);
    }
  }
  file_.reset();  // not committed: the temporary file goes, the target stays as it was
  return problem;
}

SampleLog::~SampleLog() {
  (void)close();
}

bool SampleLog::push(const LogRow& row) noexcept {
  if (queue_.push(row)) return true;
  dropped_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

void SampleLog::write_loop(std::string pending) {
  // Drains every few milliseconds: the file sees whole rows in batches, the loop never waits.
  std::uint64_t dropped_said = 0;
  for (;;) {
    const bool stopping = stop_.load();
    LogRow row;
    while (queue_.pop(row)) {
      format(row, pending);
      if (pending.size() > (64U << 10)) flush(pending);
    }
    flush(pending);
    if (const std::uint64_t d = dropped_.load(); d > 0 && dropped_said == 0) {
      dropped_said = d;  // said once, at once; close() gives the total
      io::eprint("rccx: the log {} cannot keep up: {} rows dropped so far (a slow disk?)\n", name_,
                 d);
    }
    if (stopping) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

void SampleLog::format(const LogRow& row, std::string& out) {
  auto it = std::back_inserter(out);
  fmt::format_to(it, "{:.6f},{}", row.t_s, row.segment);
  for (double q : row.commanded) fmt::format_to(it, ",{:.9g}", q);
  for (double q : row.measured) fmt::format_to(it, ",{:.9g}", q);
  const math::Transform T = kinematics_->forward(row.commanded);
  fmt::format_to(it, ",{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", T.p.x, T.p.y, T.p.z, T.R.a.x,
                 T.R.a.y, T.R.a.z);
  written_.fetch_add(1, std::memory_order_relaxed);
}

void SampleLog::flush(std::string& pending) {
  if (pending.empty()) return;
  if (error_.empty()) {
    try {
      file_->write(pending);  // whole rows only: the file always ends on a row boundary
    } catch (const io::FileError& e) {
      error_ = fmt::format("the log was not saved: {}", e.what());
      io::eprint("rccx: {}; control goes on without it\n", error_);
    }
  }
  pending.clear();
}

}  // namespace rccx::rtc
