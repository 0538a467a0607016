#include "rccx/rccl/teach.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <cmath>
#include <istream>
#include <ostream>
#include <sstream>

#include "rccx/math/units.hpp"

namespace rccx::rccl {
namespace {

using namespace std::chrono_literals;

constexpr const char* kMenu =
    "teach: Z / z zero gravity on / off   push J E S  push joint J with effort E for S s\n"
    "       m J V move joint J to V (deg, mm)   p pendant mode (J+ J- x+ x- y+ ... rx+ rz- "
    "s V q)\n"
    "       xd / xr / xR examine (deg mm / rad m / range)   X J motor parameters (Microbo)\n"
    "       h / H open / close the hand\n"
    "       save NAME store T6 in the database   e exit   ? this menu\n";

bool prismatic(const kin::Joint& j) {
  return j.type == kin::JointType::prismatic;
}

/// deg or mm (the operator's units) to rad or m.
double from_user(const kin::Joint& j, double v) {
  return prismatic(j) ? v * 1e-3 : math::deg_to_rad(v);
}

class Loop {
 public:
  Loop(Manipulator& arm, TeachIo& io) : arm_(arm), io_(io), model_(arm.kinematics().model()) {}

  Taught run() {
    arm_.waitfor(arm_.completed());  // the program's motions end first
    say("{}", kMenu);
    std::string line;
    while (prompt(pendant_ ? "pendant> " : "teach> ") && std::getline(io_.in, line)) {
      try {
        if (!(pendant_ ? pendant(line) : command(line))) return finish(true);
      } catch (const std::exception& e) {  // a bad command changes nothing; say why
        say("  {}\n", e.what());
      }
    }
    return finish(false);
  }

 private:
  template <class... Args>
  void say(fmt::format_string<Args...> f, Args&&... args) {
    io_.out << fmt::format(f, std::forward<Args>(args)...);
    io_.out.flush();
  }
  bool prompt(const char* p) {
    say("{}", p);
    return true;
  }

  [[nodiscard]] kin::JointVector q() const { return arm_.session().how().q(); }

  Taught finish(bool by_exit) {
    if (arm_.zero_gravity()) arm_.set_zero_gravity(false);
    arm_.session().wait_for(3 * arm_.session().period());
    Taught t;
    t.q = q();
    t.t6 = arm_.kinematics().forward(t.q);
    t.ended_by_exit = by_exit;
    return t;
  }

  std::size_t joint_index(int j) const {
    if (j < 1 || static_cast<std::size_t>(j) > model_.dof()) {
      throw std::invalid_argument(
          fmt::format("joint {}: the robot has joints 1 to {}", j, model_.dof()));
    }
    return static_cast<std::size_t>(j - 1);
  }

  void go(const PositionPtr& p, Mode mode) {
    if (arm_.zero_gravity()) throw std::invalid_argument("zero gravity is on: `z` first");
    const Mode before = arm_.settings().mode;
    arm_.set_mode(mode);
    const Motion m = arm_.move(p);  // MotionError says why it cannot
    arm_.set_mode(before);
    if (arm_.waitfor(m.end()) != WaitResult::reached) {
      say("  the motion did not end: {}\n",
          arm_.failures().empty() ? "control ended" : arm_.failures().back().message());
      return;
    }
    settle();
  }

  /// Lets the servos catch up with the command, so that what is examined and saved is where
  /// the arm stands (the Microbo's RCU lags by some tens of ms).
  void settle() {
    arm_.session().wait_until(
        [](const rtc::How& h) {
          for (std::size_t j = 0; j < h.dof; ++j) {
            if (std::abs(h.joint[j].velocity) > 1e-3) return false;
          }
          return true;
        },
        2s);
  }

  void move_joint(std::size_t j, double value) {
    kin::JointVector goal = q();
    goal[j] = value;
    go(Position::joints("TEACH", goal), Mode::joint);
  }

  void move_tool(const math::Transform& delta_in_base) {
    const math::Transform now = arm_.kinematics().forward(q());
    const auto t6 = rccl::t6();
    const math::Transform goal{delta_in_base.R * now.R, now.p + delta_in_base.p};
    go(Position::make("TEACH", {t6}, {rccl::constant("TEACH", goal)}, t6), Mode::cartesian);
  }

  void examine(char how) {
    const rtc::How h = arm_.session().how();
    std::string line;
    for (std::size_t j = 0; j < model_.dof(); ++j) {
      const kin::Joint& J = model_.joints[j];
      const double v = h.joint[j].q;
      if (how == 'd') {
        line += fmt::format(" {:.3f}{}", prismatic(J) ? v * 1e3 : math::rad_to_deg(v),
                            prismatic(J) ? "mm" : "deg");
      } else if (how == 'r') {
        line += fmt::format(" {:.6f}{}", v, prismatic(J) ? "m" : "rad");
      } else {
        line += fmt::format(" {:.6f}", h.joint[j].range);
      }
    }
    const math::Transform t = arm_.kinematics().forward(h.q());
    say("  joints{}\n  T6 p = ({:.3f}, {:.3f}, {:.3f}) mm, a = ({:.4f}, {:.4f}, {:.4f})\n", line,
        t.p.x * 1e3, t.p.y * 1e3, t.p.z * 1e3, t.R.a.x, t.R.a.y, t.R.a.z);
  }

  /// false: exit.
  bool command(const std::string& line) {
    std::istringstream ss(line);
    std::string c;
    if (!(ss >> c)) return true;
    if (c == "e") return false;
    if (c == "?") {
      say("{}", kMenu);
    } else if (c == "Z" || c == "z") {
      arm_.set_zero_gravity(c == "Z");
      say("  zero gravity {}\n", c == "Z" ? "on: push the arm" : "off: the arm holds");
    } else if (c == "push") {
      int j = 0;
      double effort = 0, seconds = 0;
      if (!(ss >> j >> effort >> seconds) || !(seconds > 0)) {
        throw std::invalid_argument("push J EFFORT SECONDS, e.g. push 1 5 0.5");
      }
      if (!io_.push) throw std::invalid_argument("this robot cannot be pushed by a simulated hand");
      io_.push(joint_index(j), effort);
      arm_.session().wait_for(std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(seconds)));
      io_.push(joint_index(j), 0.0);
      arm_.session().wait_for(200ms);
    } else if (c == "m") {
      int j = 0;
      double v = 0;
      if (!(ss >> j >> v)) throw std::invalid_argument("m J VALUE, e.g. m 1 30 (deg, or mm)");
      const std::size_t i = joint_index(j);
      move_joint(i, from_user(model_.joints[i], v));
    } else if (c == "p") {
      pendant_ = true;
      say("  pendant: J+ / J- jog joint J by {} deg or mm; x+ ... z- move, rx+ ... rz- turn the "
          "tool; s V sets the step; q leaves\n",
          step_);
    } else if (c == "xd" || c == "xr" || c == "xR") {
      examine(c[1] == 'd' ? 'd' : (c[1] == 'r' ? 'r' : 'R'));
    } else if (c == "X") {
      int j = 0;
      if (!(ss >> j)) throw std::invalid_argument("X J: the motor parameters of joint J");
      const std::size_t i = joint_index(j);
      arm_.send_setting({rtc::Setting::examine, static_cast<std::uint8_t>(i), 0});
      arm_.session().wait_for(4 * arm_.session().period());
      const rtc::How h = arm_.session().how();
      if (h.examined_joint != static_cast<std::int8_t>(i)) {
        throw std::invalid_argument("this robot's controllers have no motor parameters to show");
      }
      std::string values;
      for (const std::uint8_t v : h.motor_parameters) values += fmt::format(" {}", v);
      say("  joint {} motor parameters:{}\n", j, values);
    } else if (c == "h" || c == "H") {
      arm_.set_hand(c == "H");
      arm_.session().wait_for(3 * arm_.session().period());
      say("  hand {}\n", c == "H" ? "closed" : "open");
    } else if (c == "save") {
      std::string name;
      if (!(ss >> name)) throw std::invalid_argument("save NAME");
      if (io_.db == nullptr) throw std::invalid_argument("no position database (--db FILE)");
      StoredTransform t;
      t.robot = model_.name;
      t.name = name;
      t.value = arm_.kinematics().forward(q());
      t.note = "taught";
      io_.db->put(t);
      say("  saved {} for {} in {}\n", name, model_.name, io_.db->path().string());
    } else {
      throw std::invalid_argument(fmt::format("unknown command '{}' (? lists them)", c));
    }
    return true;
  }

  /// false: exit (never in pendant mode: `q` returns to the menu).
  bool pendant(const std::string& line) {
    std::istringstream ss(line);
    std::string c;
    if (!(ss >> c)) return true;
    if (c == "q") {
      pendant_ = false;
      return true;
    }
    if (c == "s") {
      double v = 0;
      if (!(ss >> v) || !(v > 0)) throw std::invalid_argument("s STEP, in deg or mm, > 0");
      step_ = v;
      say("  step {}\n", step_);
      return true;
    }
    const char sign = c.back();
    if (sign != '+' && sign != '-') {
      throw std::invalid_argument(fmt::format("pendant: '{}'? J+ J- x+ rx- s V q", c));
    }
    const double s = sign == '+' ? step_ : -step_;
    const std::string axis = c.substr(0, c.size() - 1);
    if (!axis.empty() && std::isdigit(static_cast<unsigned char>(axis[0]))) {
      const std::size_t j = joint_index(std::stoi(axis));
      move_joint(j, q()[j] + from_user(model_.joints[j], s));
      return true;
    }
    const math::Vec3 unit = axis.back() == 'x'   ? math::Vec3{1, 0, 0}
                            : axis.back() == 'y' ? math::Vec3{0, 1, 0}
                            : axis.back() == 'z' ? math::Vec3{0, 0, 1}
                                                 : math::Vec3{0, 0, 0};
    if (unit.norm() == 0 || axis.size() > 2 || (axis.size() == 2 && axis[0] != 'r')) {
      throw std::invalid_argument(fmt::format("pendant: '{}'? J+ J- x+ rx- s V q", c));
    }
    if (axis.size() == 1) {
      move_tool({math::Rot3{}, unit * (s * 1e-3)});
    } else {
      move_tool({math::Rot3::about(unit, math::deg_to_rad(s)), {}});
    }
    return true;
  }

  Manipulator& arm_;
  TeachIo& io_;
  const kin::RobotModel& model_;
  bool pendant_ = false;
  double step_ = 5.0;  ///< deg or mm
};

}  // namespace

Taught teach_loop(Manipulator& arm, TeachIo io) {
  return Loop(arm, io).run();
}

math::Transform teach_t6(Manipulator& arm, TeachIo io) {
  return teach_loop(arm, io).t6;
}

kin::JointVector teach_angles(Manipulator& arm, TeachIo io) {
  return teach_loop(arm, io).q;
}

math::Transform teach_pos(Manipulator& arm, const Position& position, TeachIo io) {
  return teach_loop(arm, io).t6 * position.tool_now();
}

math::Transform teach(Manipulator& arm, Transform& x, const Position& position, TeachIo io) {
  const std::string& robot = arm.kinematics().model().name;
  math::Transform value;
  if (io.db != nullptr) {
    if (const auto stored = io.db->get(robot, x.name())) {
      value = stored->value;
      if (x.kind() == TransformKind::hold) x.set(value);
      return value;
    }
  }
  value = position.solve_for(x, teach_loop(arm, io).t6);
  if (x.kind() == TransformKind::hold) x.set(value);
  if (io.db != nullptr) {
    StoredTransform t;
    t.robot = robot;
    t.name = x.name();
    t.value = value;
    t.note = "taught for " + position.name();
    io.db->put(t);
  }
  return value;
}

}  // namespace rccx::rccl
