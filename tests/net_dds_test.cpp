// The network layer's base (src/rccx/net/dds.hpp): two participants of one domain on loopback
// see each other's samples with the topics' QoS; bad domains are refused with a message.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include "rccx/net/dds.hpp"

using namespace rccx;
using namespace std::chrono_literals;

namespace {

/// A domain of this test process's own, so that tests running at once do not hear each other.
net::NetOptions loopback() {
  net::NetOptions o;
  o.domain = 100 + static_cast<std::uint32_t>(getpid() % 100);
  o.interface = "lo";
  return o;
}

}  // namespace

TEST(NetDds, AHeartbeatCrossesBetweenTwoParticipantsOnLoopback) {
  const net::Participant a(loopback());
  const net::Participant b(loopback());
  const net::Entity w = a.writer(net::Topic::heartbeat);
  const net::Entity r = b.reader(net::Topic::heartbeat);
  rccx_net_Heartbeat out{};
  net::copy_to(out.participant, "program/test/1");
  out.role = static_cast<std::uint8_t>(net::Role::program);
  out.seq = 42;
  bool got = false;
  // Discovery takes some ms: write until the reader has it, for at most 5 s.
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (!got && std::chrono::steady_clock::now() < until) {
    ASSERT_GE(dds_write(w.get(), &out), 0);
    rccx_net_Heartbeat in{};
    void* samples[1] = {&in};
    dds_sample_info_t info[1];
    const dds_return_t n = dds_take(r.get(), samples, info, 1, 1);
    ASSERT_GE(n, 0);
    if (n == 1 && info[0].valid_data) {
      EXPECT_STREQ(in.participant, "program/test/1");
      EXPECT_EQ(in.seq, 42U);
      got = true;
    }
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_TRUE(got) << "no heartbeat crossed in 5 s";
}

TEST(NetDds, ABadDomainIsRefusedSayingWhatToGive) {
  net::NetOptions o;
  o.domain = 300;
  try {
    const net::Participant p(o);
    FAIL() << "domain 300 accepted";
  } catch (const net::NetError& e) {
    EXPECT_NE(std::string(e.what()).find("0 .. 232"), std::string::npos) << e.what();
  }
  setenv("RCCX_DOMAIN", "seven", 1);
  EXPECT_THROW((void)net::domain_of({}), net::NetError);
  setenv("RCCX_DOMAIN", "7", 1);
  EXPECT_EQ(net::domain_of({}), 7U);
  unsetenv("RCCX_DOMAIN");
  EXPECT_EQ(net::domain_of({}), 0U);
}
