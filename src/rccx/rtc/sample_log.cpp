#include "rccx/rtc/sample_log.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cstdlib>

#include "rccx/io/console.hpp"
#include "rccx/io/parse.hpp"

#ifndef RCCX_VERSION_STRING
#error "src/CMakeLists.txt defines RCCX_VERSION_STRING, the project's version"
#endif

namespace rccx::rtc {

namespace {

constexpr std::string_view kHeaderStart = "# rccx-log 1";

/// A value as a word of the header: no space, so the line splits on spaces.
std::string escape_word(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == '%') {
      out += "%25";
    } else if (c == ' ') {
      out += "%20";
    } else {
      out += c;
    }
  }
  return out;
}

std::string unescape_word(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.substr(i, 3) == "%20") {
      out += ' ', i += 2;
    } else if (s.substr(i, 3) == "%25") {
      out += '%', i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

}  // namespace

std::string kinematics_fingerprint(const kin::RobotModel& model) {
  std::uint64_t h = 14695981039346656037ULL;  // FNV-1a, 64 bits
  const auto mix = [&h](std::string_view text) {
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ULL;
  };
  for (const kin::Joint& j : model.joints) {
    if (model.geometry == kin::Geometry::chain) {  // a URDF's: origin, axis, after
      mix(fmt::format("{} {:.17g} {:.17g} {:.17g} {:.17g};", kin::to_string(j.type),
                      fmt::join(j.chain.origin.rows(), " "), j.chain.axis.x, j.chain.axis.y,
                      j.chain.axis.z));
      mix(fmt::format("{:.17g};", fmt::join(j.chain.after.rows(), " ")));
      continue;
    }
    mix(fmt::format("{} {:.17g} {:.17g} {:.17g} {:.17g};", kin::to_string(j.type), j.dh.a_m,
                    j.dh.alpha_rad, j.dh.d_m, j.dh.theta_rad));
  }
  return fmt::format("{:016x}", h);
}

LogHeader LogHeader::of(const kin::RobotModel& model, std::string_view name,
                        std::chrono::nanoseconds period, bool simulated) {
  return LogHeader{model.name,
                   kinematics_fingerprint(model),
                   std::string(name.empty() ? std::string_view(model.name) : name),
                   period.count(),
                   simulated,
                   RCCX_VERSION_STRING};
}

std::string LogHeader::line() const {
  return fmt::format("{} robot={} kinematics={} name={} period_ns={} clock={} rccx={}\n",
                     kHeaderStart, escape_word(robot), kinematics, escape_word(name), period_ns,
                     simulated ? "simulated" : "realtime", escape_word(rccx));
}

std::optional<LogHeader> LogHeader::parse(std::string_view line) {
  if (!line.starts_with(kHeaderStart)) return std::nullopt;
  LogHeader h;
  bool clock = false;
  std::size_t pos = kHeaderStart.size();
  while (pos < line.size()) {
    const std::size_t end = std::min(line.find(' ', pos + 1), line.size());
    const std::string_view word = line.substr(pos + 1, end - pos - 1);
    pos = end;
    const std::size_t eq = word.find('=');
    if (eq == std::string_view::npos) continue;
    const std::string_view key = word.substr(0, eq);
    const std::string value = unescape_word(word.substr(eq + 1));
    if (key == "robot") h.robot = value;
    if (key == "kinematics") h.kinematics = value;
    if (key == "name") h.name = value;
    if (key == "rccx") h.rccx = value;
    if (key == "clock") h.simulated = value == "simulated", clock = true;
    if (key == "period_ns") {
      try {
        h.period_ns = io::parse_integer(value, "period_ns", 1, INT64_MAX);
      } catch (const io::ParseError& e) {
        throw LogError(fmt::format("the header's {}", e.what()));
      }
    }
  }
  const std::initializer_list<std::pair<const char*, bool>> required = {
      {"robot", !h.robot.empty()},
      {"kinematics", h.kinematics.size() == 16},
      {"name", !h.name.empty()},
      {"period_ns", h.period_ns > 0},
      {"clock", clock}};
  for (const auto& [key, given] : required) {
    if (!given) throw LogError(fmt::format("the header line has no valid {}=", key));
  }
  return h;
}

std::vector<std::string> sample_log_columns(std::size_t dof) {
  std::vector<std::string> columns{"t", "seg"};
  for (std::size_t i = 1; i <= dof; ++i) columns.push_back(fmt::format("q{}", i));
  for (std::size_t i = 1; i <= dof; ++i) columns.push_back(fmt::format("qm{}", i));
  for (const char* c : {"x", "y", "z", "ax", "ay", "az"}) columns.emplace_back(c);
  return columns;
}

SampleLog::SampleLog(const std::filesystem::path& file, const kin::RobotModel& model,
                     const LogHeader& header)
    : name_(file.string()), path_(file), kinematics_(kin::make_kinematics(model)) {
  try {
    file_ = std::make_unique<io::AtomicFile>(file);  // refuses a directory, a missing one
  } catch (const io::FileError& e) {
    throw LogError(fmt::format("cannot write the log: {}", e.what()));
  }
  // The header goes with the first rows: a disk that is full from the start is a write that
  // fails (said at once, the log not saved), not a bad file name.
  std::string head = header.line();
  fmt::format_to(std::back_inserter(head), "{}\n", fmt::join(sample_log_columns(model.dof()), ","));
  writer_ = std::thread([this, head = std::move(head)]() mutable { write_loop(std::move(head)); });
}

std::unique_ptr<SampleLog> SampleLog::from_environment(const kin::RobotModel& model,
                                                       const LogHeader& header,
                                                       std::string_view suffix) {
  const char* value = std::getenv("RCCX_LOG");
  if (value == nullptr || *value == '\0') return nullptr;
  std::filesystem::path file(value);
  if (!suffix.empty()) {
    file.replace_filename(file.stem().string() + std::string(suffix) + file.extension().string());
  }
  try {
    return std::make_unique<SampleLog>(file, model, header);
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

bool SampleLog::push(const LogRow& row, bool wait_for_room) noexcept {
  if (queue_.push(row)) return true;
  // The writer thread drains every 5 ms; it stops only at close(), after the loop has ended.
  while (wait_for_room && !stop_.load(std::memory_order_relaxed)) {
    std::this_thread::yield();
    if (queue_.push(row)) return true;
  }
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
