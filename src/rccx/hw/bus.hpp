// The wire between a driver and a robot controller, as the thesis's Multibus adapter card saw
// it (4.4.3, Appendix B): bytes read from and written to I/O addresses, and, apart from it, the
// relays the adapter did not reach (arm power, the hand, output bits: the RCU's C2 bus). A
// driver written against these talks to an emulated controller or, behind the same
// interfaces, a real one.
//
//   hw::Rcu rcu(model);                              // an emulated controller: the Relays
//   hw::RcuBus bus(rcu);                             // and its Bus
//   bus.sync(t_s);                                   // a sample begins at t_s, s
//   if ((bus.in(hw::rcu_command_register(j)) & hw::kIbe) == 0)      // one exchange each
//     bus.out(hw::rcu_command_register(j), hw::rcu::kGetPosition);
//   rcu.set_power(true);                             // a relay, not the bus
#pragma once

#include <cstdint>

namespace rccx::hw {

/// One byte in, one byte out, at an I/O address. Each call is one bus exchange.
class Bus {
 public:
  virtual ~Bus() = default;
  Bus() = default;
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;

  [[nodiscard]] virtual std::uint8_t in(std::uint16_t address) noexcept = 0;
  virtual void out(std::uint16_t address, std::uint8_t value) noexcept = 0;
  /// The sample at t_s (s) begins: a real bus has nothing to do (time passes by itself); an
  /// emulated one brings its controller's time up to t_s.
  virtual void sync(double t_s) noexcept { (void)t_s; }
};

/// Arm power, the hand and the output bits: switched by relays, not over the joint bus.
class Relays {
 public:
  virtual ~Relays() = default;
  Relays() = default;
  Relays(const Relays&) = delete;
  Relays& operator=(const Relays&) = delete;

  /// False when power cannot be switched on (a power fault).
  virtual bool set_power(bool on) noexcept = 0;
  [[nodiscard]] virtual bool power() const noexcept = 0;
  virtual void set_hand_closed(bool closed) noexcept = 0;
  [[nodiscard]] virtual bool hand_closed() const noexcept = 0;
  virtual void set_outputs(std::uint16_t bits) noexcept = 0;
  [[nodiscard]] virtual std::uint16_t outputs() const noexcept = 0;
};

}  // namespace rccx::hw
