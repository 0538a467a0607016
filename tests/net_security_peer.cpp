// A participant of net_security_test.cpp in a process of its own (a second participant in the
// test's process would share its DDS domain instance, and local delivery is no test of what
// crosses the wire): it reads RobotState and writes MotionRequests for --seconds, then says what
// it got.
//
//   net_security_peer --domain D [--secure DIR --identity NAME] --name NAME [--seconds S]
//                     [--read-state] [--write-request] [--read-answers]
// --read-answers: readers of acks and events (reliable, as a program's), never taken; a test
// stops this process (SIGSTOP) to play a frozen program whose readers acknowledge nothing.
// Prints "participant: ok" or "participant_error: <why>" (exit 3), "reader_error: <why>",
// "writer_error: <why>", and at the end "state_samples=<n>" and "requests_written=<n>".
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>

#include "rccx/net/dds.hpp"
#include "rccx/net/states.hpp"

using namespace rccx;
using namespace std::chrono_literals;

int main(int argc, char** argv) {
  net::NetOptions o;
  o.interface = "lo";
  std::string name = "peer";
  double seconds = 6.0;
  bool read_state = false;
  bool write_request = false;
  bool read_answers = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--domain") {
      o.domain = static_cast<std::uint32_t>(std::stoul(value()));
    } else if (a == "--secure") {
      o.secure_dir = value();
    } else if (a == "--identity") {
      o.secure_identity = value();
    } else if (a == "--name") {
      name = value();
    } else if (a == "--seconds") {
      seconds = std::stod(value());
    } else if (a == "--read-state") {
      read_state = true;
    } else if (a == "--write-request") {
      write_request = true;
    } else if (a == "--read-answers") {
      read_answers = true;
    } else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  std::unique_ptr<net::Participant> p;
  try {
    p = std::make_unique<net::Participant>(o);
  } catch (const net::NetError& e) {
    std::printf("participant_error: %s\n", e.what());
    return 3;
  }
  std::printf("participant: ok\n");
  net::Entity reader;
  net::Entity writer;
  if (read_state) {
    try {
      reader = p->reader(net::Topic::state);
    } catch (const net::NetError& e) {
      std::printf("reader_error: %s\n", e.what());
    }
  }
  if (write_request) {
    try {
      writer = p->writer(net::Topic::request);
    } catch (const net::NetError& e) {
      std::printf("writer_error: %s\n", e.what());
    }
  }
  net::Entity acks;
  net::Entity events;
  if (read_answers) {
    acks = p->reader(net::Topic::ack);
    events = p->reader(net::Topic::event);
    std::printf("answers: reading\n");
  }
  std::fflush(stdout);
  net::StateInbox states;
  long samples = 0;
  long written = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  unsigned long long id = 0;
  while (std::chrono::steady_clock::now() < until) {
    if (writer) {
      auto* r =
          static_cast<rccx_net_MotionRequest*>(std::calloc(1, sizeof(rccx_net_MotionRequest)));
      net::copy_to(r->robot, "puma");
      net::copy_to(r->program, name);
      r->request = ++id;
      r->kind = static_cast<std::uint8_t>(net::RequestKind::dwell);
      r->value = 0.01;
      if (dds_write(writer.get(), r) >= 0) ++written;
      std::free(r);
    }
    if (reader) {
      states.drain(reader.get(), [&](const rccx_net_RobotState& in) {
        if (std::strcmp(in.robot, "puma") == 0) ++samples;
      });
    }
    std::this_thread::sleep_for(20ms);
  }
  std::printf("state_samples=%ld\nrequests_written=%ld\n", samples, written);
  return 0;
}
