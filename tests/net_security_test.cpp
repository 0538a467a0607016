// DDS Security for rccx (issue 29, step 6; docs/NETWORK.md, "Security"), on loopback: a serve
// participant "puma" in this process writes RobotState and reads MotionRequests; programs run as
// processes of their own (net_security_peer) that read the state and write requests. A valid
// program gets through; one with no certificate, another CA's, an expired one, or permissions
// that do not cover a topic does not. Each negative test runs a valid program beside the
// rejected one in the same exchange, so it cannot pass because nothing crossed at all.
// Also `rccx certs`: the files, their modes, OpenSSL's own verdict on them, bad arguments.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <linux/if_ether.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "rccx/net/certs.hpp"
#include "rccx/net/dds.hpp"
#include "rccx/net/states.hpp"
#include "shell_run.hpp"

using namespace rccx;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {

/// A domain of this test process's own, so that tests running at once do not hear each other.
std::uint32_t test_domain() {
  return 150 + static_cast<std::uint32_t>(getpid() % 80);
}

/// The certificates of the tests, made once: DIR with puma, microbo (serve), program, and the
/// bad cases; OTHER, a second CA with its own "program"; PAYLOAD, a CA whose governance protects
/// the payloads only (Protection::payload), with puma and program.
struct Certs {
  fs::path dir;
  fs::path other;
  fs::path payload;
};

const Certs& certs() {
  static const Certs c = [] {
    char tmpl[] = "/tmp/rccx_net_security_XXXXXX";
    const char* made = mkdtemp(tmpl);
    if (made == nullptr) throw std::runtime_error("mkdtemp failed");
    static const fs::path root = made;
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(root, ec);
    });
    Certs out{root / "cell", root / "other", root / "payload"};
    net::make_ca(out.dir, {});
    for (const char* n : {"puma", "microbo", "program"}) net::issue_participant(out.dir, n, {});
    net::ParticipantOptions expired;
    expired.not_before = std::chrono::system_clock::now() - 72h;
    expired.not_after = std::chrono::system_clock::now() - 24h;
    expired.validity_of_certificate_only = true;  // its permissions are still good
    net::issue_participant(out.dir, "program-expired", expired);
    net::ParticipantOptions no_state;
    net::Grants g = net::program_grants();
    std::erase(g.subscribe, std::string(net::kStateTopic));
    no_state.grants = g;
    net::issue_participant(out.dir, "program-nostate", no_state);
    net::make_ca(out.other, {});
    net::issue_participant(out.other, "program", {});
    net::make_ca(out.payload, {.protection = net::Protection::payload});
    for (const char* n : {"puma", "program"}) net::issue_participant(out.payload, n, {});
    return out;
  }();
  return c;
}

/// One program process: its arguments and, after the run, what it printed.
struct Peer {
  std::string args;  ///< --secure ... --identity ... --name ..., or --name for a plain one
  std::string out;
  int exit_code = -1;

  [[nodiscard]] long value(const std::string& key) const {
    const std::size_t at = out.find(key + "=");
    return at == std::string::npos ? -1 : std::atol(out.c_str() + at + key.size() + 1);
  }
  [[nodiscard]] bool says(const std::string& text) const {
    return out.find(text) != std::string::npos;
  }
};

Peer secure_peer(const fs::path& dir, const std::string& identity, const std::string& name,
                 const std::string& what = "--read-state --write-request") {
  Peer p;
  p.args = "--secure " + dir.string() + " --identity " + identity + " --name " + name + " " + what;
  return p;
}

/// What puma saw: the programs whose requests it read.
struct Exchange {
  std::set<std::string> requests_from;
  long state_written = 0;
};

/// Runs puma (secure with `dir`'s files, in this process) while `peers` run for `seconds` each in
/// processes of their own, all at once; fills in each peer's output.
Exchange run_exchange(std::vector<Peer>& peers, double seconds = 6.0,
                      const fs::path& dir = certs().dir) {
  net::NetOptions o;
  o.domain = test_domain();
  o.interface = "lo";
  o.secure_dir = dir;
  o.secure_identity = "puma";
  const net::Participant puma(o);
  const net::Entity state = puma.writer(net::Topic::state);
  const net::Entity requests = puma.reader(net::Topic::request);
  std::vector<std::thread> threads;
  std::atomic<std::size_t> done{0};
  for (Peer& p : peers) {
    threads.emplace_back([&p, &done, seconds] {
      const test::ShellRun r = test::run_shell(std::string(RCCX_NET_PEER) + " --domain " +
                                               std::to_string(test_domain()) + " --seconds " +
                                               std::to_string(seconds) + " " + p.args + " 2>&1");
      p.out = r.out;
      p.exit_code = r.exit_code;
      ++done;
    });
  }
  Exchange ex;
  net::StateBatch batch("serve/test", 1, 1);
  // The peers end by themselves after `seconds` (plus their start); puma serves until then.
  const auto until =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds) + 30s;
  while (done < peers.size() && std::chrono::steady_clock::now() < until) {
    rccx_net_RobotState& s = batch.add();
    net::copy_to(s.robot, "puma");
    net::copy_to(s.participant, "serve/test");
    s.sample = static_cast<unsigned long long>(++ex.state_written);
    EXPECT_GE(batch.write(state.get()), 0);
    auto* in = static_cast<rccx_net_MotionRequest*>(std::calloc(1, sizeof(rccx_net_MotionRequest)));
    void* samples[1] = {in};
    dds_sample_info_t info[1];
    while (dds_take(requests.get(), samples, info, 1, 1) == 1) {
      if (info[0].valid_data) ex.requests_from.insert(in->program);
    }
    dds_sample_free(in, &rccx_net_MotionRequest_desc,
                    DDS_FREE_ALL);  // and any sequence Cyclone filled
    std::this_thread::sleep_for(20ms);
  }
  for (std::thread& t : threads) t.join();
  return ex;
}

/// The valid program of an exchange did get through: the positive control.
void expect_valid_program_got_through(const Peer& valid, const Exchange& ex) {
  EXPECT_EQ(valid.exit_code, 0) << valid.out;
  EXPECT_GT(valid.value("state_samples"), 0) << "the valid program read no state:\n" << valid.out;
  EXPECT_TRUE(ex.requests_from.count("program") == 1)
      << "puma read no request of the valid program:\n"
      << valid.out;
}

/// `rejected` got nothing: no state read, no request of `name` read by puma.
void expect_rejected(const Peer& rejected, const std::string& name, const Exchange& ex) {
  EXPECT_LE(rejected.value("state_samples"), 0) << rejected.out;
  EXPECT_EQ(ex.requests_from.count(name), 0U) << name << "'s requests reached puma";
}

/// Every packet on loopback while it lives (an AF_PACKET socket: root or CAP_NET_RAW), searched
/// for byte strings: what crossed the wire in clear. Packets go both ways on "lo", so each is
/// seen twice.
class LoopbackSniffer {
 public:
  explicit LoopbackSniffer(std::vector<std::string> needles) : needles_(std::move(needles)) {
    fd_ = socket(AF_PACKET, SOCK_RAW | SOCK_CLOEXEC, htons(ETH_P_ALL));
    if (fd_ < 0) {
      why_not_ = std::string("an AF_PACKET socket: ") + std::strerror(errno) +
                 " (needs root or CAP_NET_RAW)";
      return;
    }
    sockaddr_ll at{};
    at.sll_family = AF_PACKET;
    at.sll_protocol = htons(ETH_P_ALL);
    at.sll_ifindex = static_cast<int>(if_nametoindex("lo"));
    if (at.sll_ifindex == 0 || bind(fd_, reinterpret_cast<sockaddr*>(&at), sizeof at) != 0) {
      why_not_ = std::string("binding to lo: ") + std::strerror(errno);
      return;
    }
    timeval tv{0, 100'000};  // recv wakes to see stop_
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    found_.assign(needles_.size(), 0);
    thread_ = std::thread([this] {
      std::vector<char> buf(1 << 16);
      while (!stop_) {
        const ssize_t n = recv(fd_, buf.data(), buf.size(), 0);
        if (n <= 0) continue;
        const std::string_view pkt(buf.data(), static_cast<std::size_t>(n));
        if (pkt.find("RTPS") != std::string_view::npos) ++rtps_packets_;
        for (std::size_t i = 0; i < needles_.size(); ++i) {
          if (pkt.find(needles_[i]) != std::string_view::npos) ++found_[i];
        }
      }
    });
  }
  ~LoopbackSniffer() {
    stop();
    if (fd_ >= 0) close(fd_);
  }
  LoopbackSniffer(const LoopbackSniffer&) = delete;
  LoopbackSniffer& operator=(const LoopbackSniffer&) = delete;
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  /// Empty when sniffing; else why not.
  [[nodiscard]] const std::string& why_not() const { return why_not_; }
  /// After stop(): packets with RTPS's magic seen, and packets holding needle i.
  [[nodiscard]] long rtps_packets() const { return rtps_packets_; }
  [[nodiscard]] long found(std::size_t i) const { return found_[i]; }

 private:
  std::vector<std::string> needles_;
  std::vector<long> found_;
  long rtps_packets_ = 0;
  int fd_ = -1;
  std::string why_not_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace

TEST(NetSecurity, TwoValidParticipantsExchangeStateAndRequests) {
  std::vector<Peer> peers{secure_peer(certs().dir, "program", "program")};
  const Exchange ex = run_exchange(peers);
  expect_valid_program_got_through(peers[0], ex);
  EXPECT_TRUE(peers[0].says("participant: ok")) << peers[0].out;
  EXPECT_FALSE(peers[0].says("_error")) << peers[0].out;
}

TEST(NetSecurity, AParticipantWithNoCertificateNeitherReadsStateNorCommands) {
  std::vector<Peer> peers{secure_peer(certs().dir, "program", "program"),
                          Peer{"--name plain --read-state --write-request", "", -1}};
  const Exchange ex = run_exchange(peers);
  expect_valid_program_got_through(peers[0], ex);
  // It runs (plain DDS is allowed on its own) but sees nothing of the secured domain.
  EXPECT_TRUE(peers[1].says("participant: ok")) << peers[1].out;
  EXPECT_GT(peers[1].value("requests_written"), 0) << peers[1].out;
  expect_rejected(peers[1], "plain", ex);
}

TEST(NetSecurity, AParticipantOfAnotherCaNeitherReadsStateNorCommands) {
  std::vector<Peer> peers{secure_peer(certs().dir, "program", "program"),
                          secure_peer(certs().other, "program", "intruder")};
  const Exchange ex = run_exchange(peers);
  expect_valid_program_got_through(peers[0], ex);
  // Its own CA vouches for it, so it starts; puma's identity CA does not, so the handshake fails.
  EXPECT_TRUE(peers[1].says("participant: ok")) << peers[1].out;
  EXPECT_GT(peers[1].value("requests_written"), 0) << peers[1].out;
  expect_rejected(peers[1], "intruder", ex);
}

TEST(NetSecurity, AnExpiredCertificateIsRefused) {
  std::vector<Peer> peers{secure_peer(certs().dir, "program", "program"),
                          secure_peer(certs().dir, "program-expired", "expired")};
  const Exchange ex = run_exchange(peers);
  expect_valid_program_got_through(peers[0], ex);
  // Cyclone refuses its own identity at once: the participant is not made.
  EXPECT_EQ(peers[1].exit_code, 3) << peers[1].out;
  EXPECT_TRUE(peers[1].says("participant_error")) << peers[1].out;
  // Cyclone says why in its log (the participant's error is only "Error").
  EXPECT_TRUE(peers[1].says("certificate has expired")) << peers[1].out;
  expect_rejected(peers[1], "expired", ex);
}

TEST(NetSecurity, APermissionsFileWithoutStateCannotReadIt) {
  std::vector<Peer> peers{secure_peer(certs().dir, "program", "program"),
                          secure_peer(certs().dir, "program-nostate", "nostate")};
  const Exchange ex = run_exchange(peers);
  expect_valid_program_got_through(peers[0], ex);
  // Its permissions name no rule for rccx_state, and the default is DENY: even the topic is
  // refused, so rccx's participant (which makes every topic) is not made.
  EXPECT_EQ(peers[1].exit_code, 3) << peers[1].out;
  EXPECT_TRUE(peers[1].says("participant_error: DDS topic rccx_state: Not Allowed By Security"))
      << peers[1].out;
  expect_rejected(peers[1], "nostate", ex);
}

TEST(NetSecurity, AServeProcessCannotSendMotionRequests) {
  std::vector<Peer> peers{secure_peer(certs().dir, "program", "program"),
                          secure_peer(certs().dir, "microbo", "microbo")};
  const Exchange ex = run_exchange(peers);
  expect_valid_program_got_through(peers[0], ex);
  // A serve process reads requests but may not publish them: its writer is refused.
  EXPECT_TRUE(peers[1].says("participant: ok")) << peers[1].out;
  EXPECT_TRUE(peers[1].says("writer_error: a writer of rccx_request: Not Allowed By Security"))
      << peers[1].out;
  EXPECT_EQ(peers[1].value("requests_written"), 0) << peers[1].out;
  EXPECT_EQ(ex.requests_from.count("microbo"), 0U);
  // Serves read each other's state (frames, collision checks): that it may.
  EXPECT_GT(peers[1].value("state_samples"), 0) << peers[1].out;
}

// Protection::payload leaves the headers clear: it must still keep out a participant with no
// certificate or another CA's, and nothing of the data may cross loopback in clear. The state's
// participant and the program's name are inside the payloads only.
TEST(NetSecurity, PayloadProtectionKeepsOutTheUncertifiedAndSendsNoDataInClear) {
  const std::string program_name = "prog-q7Zx3k";  // MotionRequest::program, in its payload
  const std::string state_marker = "serve/test";   // RobotState::participant (run_exchange)
  LoopbackSniffer sniffer({program_name, state_marker});
  if (!sniffer.why_not().empty()) GTEST_SKIP() << "cannot watch loopback: " << sniffer.why_not();
  std::vector<Peer> peers{secure_peer(certs().payload, "program", program_name),
                          Peer{"--name plain --read-state --write-request", "", -1},
                          secure_peer(certs().other, "program", "intruder")};
  const Exchange ex = run_exchange(peers, 6.0, certs().payload);
  sniffer.stop();
  EXPECT_EQ(peers[0].exit_code, 0) << peers[0].out;
  EXPECT_GT(peers[0].value("state_samples"), 0) << "the valid program read no state:\n"
                                                << peers[0].out;
  EXPECT_EQ(ex.requests_from.count(program_name), 1U) << "puma read no request of the program";
  expect_rejected(peers[1], "plain", ex);
  expect_rejected(peers[2], "intruder", ex);
  // The sniffer saw the traffic (hundreds of states and requests, each seen twice), and no data.
  EXPECT_GT(sniffer.rtps_packets(), 200) << "the sniffer missed the exchange";
  EXPECT_EQ(sniffer.found(0), 0) << "a request's program name crossed loopback in clear";
  EXPECT_EQ(sniffer.found(1), 0) << "a state's payload crossed loopback in clear";
}

TEST(NetSecurity, AMissingFileIsNamedWithTheCommandToRun) {
  net::NetOptions o;
  o.domain = test_domain();
  o.interface = "lo";
  o.secure_dir = certs().dir;
  o.secure_identity = "nobody";
  try {
    const net::Participant p(o);
    FAIL() << "a participant without files was made";
  } catch (const net::NetError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("nobody/cert.pem"), std::string::npos) << what;
    EXPECT_NE(what.find("rccx certs init"), std::string::npos) << what;
  }
  o.secure_identity = "../cell";
  EXPECT_THROW(net::Participant{o}, net::NetError);
}

// ---- rccx certs -------------------------------------------------------------------------------

namespace {

unsigned mode_of(const fs::path& p) {
  struct stat st {};
  if (stat(p.c_str(), &st) != 0) return 0;
  return st.st_mode & 07777U;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = certs().dir.parent_path() / name;
  fs::remove_all(d);
  return d;
}

std::string text_of(const fs::path& p) {
  std::stringstream s;
  s << std::ifstream(p).rdbuf();
  return s.str();
}

/// Whether the permissions file `p` lets its participant publish `topic`.
bool publishes(const fs::path& p, const std::string& topic) {
  const std::string t = text_of(p);
  const std::size_t from = t.find("<publish>");
  const std::size_t to = t.find("</publish>");
  const std::size_t at = t.find("<topic>" + topic + "</topic>", from);
  return from != std::string::npos && at != std::string::npos && at < to;
}

bool have_openssl() {
  return test::run_shell("command -v openssl >/dev/null 2>&1").exit_code == 0;
}

}  // namespace

TEST(NetSecurityCli, InitMakesEveryFileWithPrivateModes) {
  const fs::path d = fresh_dir("cli");
  const test::ShellRun r =
      test::rccx_run("certs init " + d.string() + " --participants puma,microbo,program --days 30");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  for (const char* f : {"identity_ca.pem", "permissions_ca.pem", "governance.p7s"}) {
    EXPECT_TRUE(fs::is_regular_file(d / f)) << f;
  }
  for (const char* n : {"puma", "microbo", "program"}) {
    for (const char* f : {"cert.pem", "key.pem", "permissions.p7s"}) {
      EXPECT_TRUE(fs::is_regular_file(d / n / f)) << n << "/" << f;
    }
    EXPECT_EQ(mode_of(d / n / "key.pem"), 0600U) << n;
  }
  EXPECT_EQ(mode_of(d / "private"), 0700U);
  EXPECT_EQ(mode_of(d / "private" / "identity_ca_key.pem"), 0600U);
  EXPECT_EQ(mode_of(d / "private" / "permissions_ca_key.pem"), 0600U);
  // "program" got the program's grants, "puma" the serve's (S/MIME text has CRLF line ends).
  EXPECT_TRUE(publishes(d / "program" / "permissions.p7s", "rccx_request"));
  EXPECT_FALSE(publishes(d / "program" / "permissions.p7s", "rccx_state"));
  EXPECT_FALSE(publishes(d / "puma" / "permissions.p7s", "rccx_request"));
  EXPECT_TRUE(publishes(d / "puma" / "permissions.p7s", "rccx_state"));
  EXPECT_NE(text_of(d / "puma" / "permissions.p7s").find("CN=puma"), std::string::npos);

  // More participants later, from the CA's kept keys.
  const test::ShellRun add =
      test::rccx_run("certs add " + d.string() + " --participant cam --program");
  EXPECT_EQ(add.exit_code, 0) << add.out;
  EXPECT_TRUE(fs::is_regular_file(d / "cam" / "cert.pem"));

  if (!have_openssl()) GTEST_SKIP() << "no openssl binary here: its verification is not run";
  for (const char* n : {"puma", "program", "cam"}) {
    const test::ShellRun v =
        test::run_shell("openssl verify -CAfile " + (d / "identity_ca.pem").string() + " " +
                        (d / n / "cert.pem").string() + " 2>&1");
    EXPECT_EQ(v.exit_code, 0) << v.out;
    const test::ShellRun p =
        test::run_shell("openssl smime -verify -in " + (d / n / "permissions.p7s").string() +
                        " -CAfile " + (d / "permissions_ca.pem").string() + " -out /dev/null 2>&1");
    EXPECT_EQ(p.exit_code, 0) << p.out;
  }
  const test::ShellRun g =
      test::run_shell("openssl smime -verify -in " + (d / "governance.p7s").string() + " -CAfile " +
                      (d / "permissions_ca.pem").string() + " 2>/dev/null");
  EXPECT_EQ(g.exit_code, 0) << g.out;
  EXPECT_NE(g.out.find("<allow_unauthenticated_participants>false"), std::string::npos) << g.out;
  // Another CA's certificate does not verify against this one.
  const test::ShellRun other =
      test::run_shell("openssl verify -CAfile " + (d / "identity_ca.pem").string() + " " +
                      (certs().other / "program" / "cert.pem").string() + " 2>&1");
  EXPECT_NE(other.exit_code, 0) << other.out;
}

TEST(NetSecurityCli, ProtectionChoosesWhatTheGovernanceEncrypts) {
  // The governance's XML is in clear inside its S/MIME file (CRLF line ends).
  const fs::path full = fresh_dir("cli-full");
  ASSERT_EQ(test::rccx_run("certs init " + full.string() + " --participants puma").exit_code, 0);
  const std::string f = text_of(full / "governance.p7s");
  EXPECT_NE(f.find("<rtps_protection_kind>ENCRYPT"), std::string::npos) << f;
  EXPECT_NE(f.find("<metadata_protection_kind>ENCRYPT"), std::string::npos) << f;
  EXPECT_EQ(f.find("_protection_kind>NONE"), std::string::npos) << f;
  const fs::path payload = fresh_dir("cli-payload");
  const test::ShellRun r = test::rccx_run("certs init " + payload.string() +
                                          " --participants puma --protection payload");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("payload protection"), std::string::npos) << r.out;
  const std::string p = text_of(payload / "governance.p7s");
  EXPECT_NE(p.find("<rtps_protection_kind>NONE"), std::string::npos) << p;
  EXPECT_NE(p.find("<metadata_protection_kind>NONE"), std::string::npos) << p;
  EXPECT_NE(p.find("<data_protection_kind>ENCRYPT"), std::string::npos) << p;
  EXPECT_EQ(p.find("<data_protection_kind>NONE"), std::string::npos) << p;
  EXPECT_NE(p.find("<discovery_protection_kind>ENCRYPT"), std::string::npos) << p;
  EXPECT_NE(p.find("<allow_unauthenticated_participants>false"), std::string::npos) << p;
}

TEST(NetSecurityCli, AnExistingCaIsKeptUnlessForced) {
  const fs::path d = fresh_dir("cli-force");
  ASSERT_EQ(test::rccx_run("certs init " + d.string() + " --participants puma").exit_code, 0);
  std::stringstream before;
  before << std::ifstream(d / "identity_ca.pem").rdbuf();
  const test::ShellRun again = test::rccx_run("certs init " + d.string() + " --participants puma");
  EXPECT_EQ(again.exit_code, 2) << again.out;
  EXPECT_NE(again.out.find("--force"), std::string::npos) << again.out;
  std::stringstream after;
  after << std::ifstream(d / "identity_ca.pem").rdbuf();
  EXPECT_EQ(before.str(), after.str()) << "a refused init changed the CA";
  const test::ShellRun forced =
      test::rccx_run("certs init " + d.string() + " --participants puma --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.out;
  std::stringstream replaced;
  replaced << std::ifstream(d / "identity_ca.pem").rdbuf();
  EXPECT_NE(before.str(), replaced.str());
}

TEST(NetSecurityCli, BadArgumentsExitTwoAndWriteNothing) {
  const fs::path d = fresh_dir("cli-bad");
  const std::vector<std::string> bad{
      "certs init " + d.string() + " --participants 'pu ma'",
      "certs init " + d.string() + " --participants puma,puma",
      "certs init " + d.string() + " --participants puma,../x",
      "certs init " + d.string() + " --participants private",
      "certs init " + d.string() + " --participants puma --days 0",
      "certs init " + d.string() + " --participants puma --protection none",
      "certs init " + d.string(),
      "certs init --participants puma",
      "certs add " + d.string() + " --participant puma",
      "certs frobnicate"};
  for (const std::string& args : bad) {
    const test::ShellRun r = test::rccx_run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.out;
    EXPECT_NE(r.out.find("error:"), std::string::npos) << args << "\n" << r.out;
  }
  EXPECT_FALSE(fs::exists(d)) << "a refused command wrote " << d;
  const test::ShellRun help = test::rccx_run("certs init --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--participants"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("--force"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("--protection"), std::string::npos) << help.out;
}
