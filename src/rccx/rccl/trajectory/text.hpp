// text(): a message made in the sample loop, by value (io::format_fixed: no allocation, cut to
// kEventText - 1 characters). For the generator's .cpp files only: it brings in fmt, which the
// headers that everyone includes leave out.
//
//   fail(id, ctx, kin::IkStatus::ok, 0, text("halted at t = {:.3f} s", t));
#pragma once

#include <utility>

#include "rccx/io/fixed_text.hpp"
#include "rccx/rccl/trajectory/failure.hpp"

namespace rccx::rccl::trajectory {

template <class... Args>
Text text(fmt::format_string<Args...> f, Args&&... args) noexcept {
  Text to{};
  io::format_fixed(to, f, std::forward<Args>(args)...);
  return to;
}

}  // namespace rccx::rccl::trajectory
