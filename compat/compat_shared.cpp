// The RCCL level's side of compat_shared.hpp.
#include "compat_shared.hpp"

namespace rccx::compat {

bool rccl_session_open() noexcept {
  return false;  // replaced when merged: true while rccl_open's session or a cell is open
}

}  // namespace rccx::compat
