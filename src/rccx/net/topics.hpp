// rccx's DDS topics: their names, the numbering of the octet fields of rccx_net.idl, the QoS
// of each (the one place they are chosen; docs/NETWORK.md explains them) and the options every
// participant shares. The generated C types are "rccx_net.h" (idlc, in the build tree).
//
//   topic                 type          QoS
//   rccx_heartbeat        Heartbeat     best effort, keep last 1, liveliness automatic (lease =
//                                       detection time); a peer silent that long is lost
//   rccx_claim            Claim         reliable, transient local, keep last 1
//   rccx_state            ServeStates   best effort, keep last 1, deadline (the detection time):
//                                       a serve's robots' RobotStates, one sample a pass
//   rccx_request          MotionRequest reliable, keep all, volatile (ordered per writer)
//   rccx_ack              MotionAck     reliable, keep last kAckDepth, never blocking the writer
//   rccx_event            MotionEvent   reliable, keep last kEventDepth, never blocking the writer
//   rccx_frame            FrameSample   best effort, keep last 1
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace rccx::net {

/// A network failure: a participant, topic, reader or writer that could not be made, a write
/// refused. The message says what and what to do.
class NetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr const char* kHeartbeatTopic = "rccx_heartbeat";
inline constexpr const char* kClaimTopic = "rccx_claim";
inline constexpr const char* kStateTopic = "rccx_state";
inline constexpr const char* kRequestTopic = "rccx_request";
inline constexpr const char* kAckTopic = "rccx_ack";
inline constexpr const char* kEventTopic = "rccx_event";
inline constexpr const char* kFrameTopic = "rccx_frame";

/// Acks kept per (robot, program) instance until every reader has them: a program waits for
/// each answer before its next request to a robot, so a live one never has this many unread.
inline constexpr int kAckDepth = 64;
/// Events kept per robot until every reader has them (each motion has two or three).
inline constexpr int kEventDepth = 256;

/// Heartbeat::role
enum class Role : std::uint8_t { serve = 0, program = 1 };
/// RobotState::status
enum class RobotStatus : std::uint8_t {
  not_started = 0,  ///< control not running yet
  at_rest = 1,      ///< controlling, nothing moving
  moving = 2,       ///< a motion runs
  stopping = 3,     ///< halting (a halt, a lost link, a collision stop)
  ended = 4,        ///< control ended: see terminate_code / termination
};
/// Term::kind
enum class TermKind : std::uint8_t {
  constant = 0,  ///< value by value
  hold = 1,      ///< by value: the value it had when the program asked
  t6 = 2,
  frame = 3,     ///< name: a robot of the cell; its commanded T6 TOOL in the world
  function = 4,  ///< name: a functional transform registered in the serve process
  stream = 5,    ///< name: a FrameSample stream the program writes
};
/// MotionRequest::kind
enum class RequestKind : std::uint8_t {
  move = 0,
  dwell = 1,     ///< value: s
  halt = 2,      ///< stop smoothly where the arm is, cancel everything queued
  hand = 3,      ///< value: 1 close, 0 open
  nextmove = 4,  ///< end the running motion, go on with the next
  attach = 5,    ///< the program takes the robot (no motion): its loss now stops it
};
/// MotionAck::result
enum class AckResult : std::uint8_t { accepted = 0, duplicate = 1, refused = 2 };

/// Where DDS runs and how a lost peer is told.
struct NetOptions {
  /// DDS domain: 0 .. 232. Default: $RCCX_DOMAIN, else 0.
  std::optional<std::uint32_t> domain;
  /// The network interface DDS uses ("lo", "eth0", an address); empty: Cyclone's choice, or
  /// $RCCX_DDS_INTERFACE. "lo" adds 127.0.0.1 as a unicast peer (loopback has no multicast).
  std::string interface;
  /// A peer (serve process or program) silent this long is lost: its robots stop smoothly
  /// (serve side), or its robots' motions fail (program side).
  std::chrono::nanoseconds detection = std::chrono::milliseconds(20);
  /// How often this participant says it is alive (a quarter of detection by default).
  std::chrono::nanoseconds heartbeat = std::chrono::milliseconds(5);
  /// DDS Security's files for this participant (rccx certs init DIR); empty: plain, unsecured.
  std::filesystem::path secure_dir;
  /// This participant's name in secure_dir (its certificate and permissions), e.g. "puma".
  std::string secure_identity;
};

/// The domain: options.domain, else $RCCX_DOMAIN (checked: 0 .. 232), else 0. Throws NetError
/// for a bad $RCCX_DOMAIN.
std::uint32_t domain_of(const NetOptions& options);

}  // namespace rccx::net
