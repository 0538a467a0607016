// The files DDS Security needs, made with OpenSSL's libcrypto (docs/NETWORK.md, "Security"):
// an identity CA and a permissions CA, each participant's key and certificate, the governance
// and each participant's permissions, both signed by the permissions CA as Cyclone reads them.
//
//   net::make_ca("cell-certs", {});                      // rccx certs init cell-certs ...
//   net::issue_participant("cell-certs", "puma", {});    //   --participants puma,...
//   net::issue_participant("cell-certs", "program", {}); // "program*": the program's grants
//   NetOptions o; o.secure_dir = "cell-certs"; o.secure_identity = "puma";
//
// DIR/identity_ca.pem, permissions_ca.pem, governance.p7s: what every participant trusts.
// DIR/<name>/cert.pem, key.pem (0600), permissions.p7s: one participant's.
// DIR/private/ (0700): the CAs' keys, so that participants can be added later (rccx certs add).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rccx/net/topics.hpp"

namespace rccx::net {

/// The highest DDS domain a secure participant may use (Cyclone's access control reads 0 .. 230).
inline constexpr std::uint32_t kMaxSecureDomain = 230;

/// What a participant may publish and subscribe (topic names, "rt/*" patterns allowed).
struct Grants {
  std::vector<std::string> publish;
  std::vector<std::string> subscribe;
};

/// A program's grants: requests, frames and heartbeats out; state, acks, events, heartbeats and
/// claims in.
Grants program_grants();
/// A serve process's grants: state, acks, events, claims, heartbeats and ROS 2's rt/* out;
/// requests, frames, heartbeats, claims and the other serves' state in.
Grants serve_grants();

/// The role a participant's name gives it: "program..." is a program, others serve processes.
Role role_of(std::string_view name);

/// How much of each message DDS Security protects: the governance's protection kinds. Both
/// authenticate every participant, control who reads and writes each topic, and encrypt
/// discovery, liveliness and every topic's data (AES-GCM: a payload changed on the way is
/// refused).
enum class Protection : std::uint8_t {
  /// Also every RTPS message and every submessage encrypted (sequence numbers, heartbeats,
  /// acknowledgements): ROS 2's sros2 default. About 3x a plain round trip (docs/PERFORMANCE.md).
  full,
  /// The payloads only: the messages' and submessages' headers stay clear, so someone on the
  /// network sees who talks to whom and when, and could disturb reliable delivery (a denial of
  /// service), but reads and forges no data. About 1.4x a plain round trip.
  payload,
};

struct CaOptions {
  int days = 3650;     ///< the CAs' validity, days from now
  bool force = false;  ///< replace the CA of DIR (every participant of it must be issued again)
  Protection protection = Protection::full;  ///< the governance's
};

/// Makes DIR's identity CA and permissions CA (EC P-256, self-signed X.509 v3), their keys in
/// DIR/private/, and the governance (governance_xml()) signed by the permissions CA. Refuses
/// (NetError, nothing written) when DIR has a CA already, unless options.force.
void make_ca(const std::filesystem::path& dir, const CaOptions& options);

struct ParticipantOptions {
  /// The role's grants when empty (role_of the name, or `role` when given).
  std::optional<Grants> grants;
  std::optional<Role> role;
  /// The certificate's and permissions' validity. Default: from an hour ago (clocks of hosts
  /// differ a little) to `days` from now.
  int days = 365;
  std::optional<std::chrono::system_clock::time_point> not_before;
  std::optional<std::chrono::system_clock::time_point> not_after;
  /// Only the certificate's validity changes with not_before / not_after (tests of an expired
  /// certificate whose permissions are still good); false: both.
  bool validity_of_certificate_only = false;
};

/// Issues participant `name` ([A-Za-z0-9_-], 1 to 32 characters) of DIR: its key, certificate
/// (CN=<name>, O=rccx) signed by DIR's identity CA, and permissions signed by DIR's permissions
/// CA. Replaces the participant's files if it had them. Throws NetError (bad name, no CA in DIR,
/// OpenSSL's failure).
void issue_participant(const std::filesystem::path& dir, const std::string& name,
                       const ParticipantOptions& options);

/// Checks a participant's name; throws NetError saying what is allowed.
void check_participant_name(std::string_view name);

/// The governance document (DDS Security 1.1) rccx uses; docs/NETWORK.md explains it.
std::string governance_xml(Protection protection = Protection::full);
/// The permissions document of the participant whose certificate subject is `subject`
/// ("/O=rccx/CN=puma", as OpenSSL writes it on one line), valid from `from` to `to`.
std::string permissions_xml(const std::string& subject, const Grants& grants,
                            std::chrono::system_clock::time_point from,
                            std::chrono::system_clock::time_point to);

}  // namespace rccx::net
