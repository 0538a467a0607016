// Positions, settings and poses as rccx_net.idl carries them (docs/NETWORK.md, "Positions").
// A motion request carries its whole equation: constant and hold transforms by value, T6, and
// functional transforms by the name their Transform::reference() gives them:
//
//   frame:<robot>     that robot's commanded T6 TOOL in the world (cell.tool_frame(robot))
//   function:<name>   a function registered in the serve process (RobotServer::register_function)
//   stream:<name>     the newest FrameSample a program writes (RemoteCell::stream(name))
//
//   net::RequestSample r;
//   net::encode_position(*goal, r);            // the program: throws CodecError for what cannot go
//   dds_write(writer, &r.msg);
//   rccl::PositionPtr p = net::decode_position(taken, resolve);   // the serve: a new equation
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "rccx/math/transform.hpp"
#include "rccx/net/topics.hpp"
#include "rccx/rccl/position.hpp"
#include "rccx/rccl/trajectory/requests.hpp"
#include "rccx_net.h"

namespace rccx::net {

/// What cannot be sent or was received malformed; the message says what and how to fix it.
class CodecError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The bounds of MotionRequest's sequences (rccx_net.idl).
inline constexpr std::size_t kTermsPerSide = 8;  ///< sequence<Term, 8> lhs, rhs
inline constexpr std::size_t kGates = 4;         ///< sequence<Gate, 4> after

/// A MotionRequest to write, with room for its terms and gates: `msg`'s sequences point into this
/// object (_release false, so nothing frees them through it), so building and writing one
/// allocates nothing. Copying re-points the copy's sequences at its own storage.
struct RequestSample {
  rccx_net_MotionRequest msg{};
  RequestSample() noexcept { point(); }
  RequestSample(const RequestSample& o) noexcept { *this = o; }
  RequestSample& operator=(const RequestSample& o) noexcept;
  /// Appends a zeroed term to lhs or rhs / a gate (the caller checked the bound).
  rccx_net_Term& add_lhs() noexcept { return lhs_[msg.lhs._length++] = rccx_net_Term{}; }
  rccx_net_Term& add_rhs() noexcept { return rhs_[msg.rhs._length++] = rccx_net_Term{}; }
  rccx_net_Gate& add_gate() noexcept { return gates_[msg.after._length++] = rccx_net_Gate{}; }

 private:
  void point() noexcept;
  rccx_net_Term lhs_[kTermsPerSide]{};
  rccx_net_Term rhs_[kTermsPerSide]{};
  rccx_net_Gate gates_[kGates]{};
};

void to_pose(const math::Transform& t, rccx_net_Pose& out) noexcept;
[[nodiscard]] math::Transform from_pose(const rccx_net_Pose& p) noexcept;

/// A functional transform's reference split: "frame:puma" -> {frame, "puma"}. Throws CodecError
/// for an empty or unknown reference, naming the transform and how to name it.
struct Reference {
  TermKind kind = TermKind::function;
  std::string name;
};
[[nodiscard]] Reference parse_reference(const rccl::Transform& t);

/// Writes `p` into the request's position fields (position, in_joints, dof, joints, lhs, rhs,
/// tool). Throws CodecError (the request untouched) for a functional transform without a
/// reference, more than kTermsPerSide terms a side, or a name longer than 31 characters.
void encode_position(const rccl::Position& p, RequestSample& r);

/// Makes the transform a received functional term stands for: `kind` frame, function or stream
/// with its name. Throws (CodecError or std::invalid_argument) to refuse it, saying why.
using Resolver = std::function<rccl::TransformPtr(TermKind kind, std::string_view name)>;

/// The position of a request: a new equation whose constant and hold terms carry the values
/// sent, T6, and functional terms from `resolve`. Throws CodecError for a malformed request (a
/// side longer than its bound, a tool index outside lhs),
/// rccl::EquationError for a bad equation, what `resolve` throws.
[[nodiscard]] rccl::PositionPtr decode_position(const rccx_net_MotionRequest& r,
                                                const Resolver& resolve);

/// The settings of a request (mode, speeds, times, configuration, guard, compliance, touch).
void encode_settings(const rccl::MotionSettings& s, rccx_net_MotionRequest& r) noexcept;
[[nodiscard]] rccl::MotionSettings decode_settings(const rccx_net_MotionRequest& r) noexcept;

/// A bounded IDL string as a string_view (up to its NUL or N).
template <std::size_t N>
[[nodiscard]] std::string_view text_of(const char (&s)[N]) noexcept {
  std::size_t n = 0;
  while (n < N && s[n] != '\0') ++n;
  return {s, n};
}

}  // namespace rccx::net
