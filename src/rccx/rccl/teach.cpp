#include "rccx/rccl/teach.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <algorithm>
#include <cmath>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <vector>

#include "rccx/io/input.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/io/signals.hpp"
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

/// deg or mm (the operator's units) to rad or m, and back.
double from_user(const kin::Joint& j, double v) {
  return prismatic(j) ? v * 1e-3 : math::deg_to_rad(v);
}
double to_user(const kin::Joint& j, double v) {
  return prismatic(j) ? v * 1e3 : math::rad_to_deg(v);
}
const char* user_unit(const kin::Joint& j) {
  return prismatic(j) ? "mm" : "deg";
}

/// A target for joint `j` in the operator's units, refused outside the joint's limits.
double joint_goal(std::string_view text, const kin::Joint& j, std::size_t index) {
  const std::string what = fmt::format("m: joint {} ({}) target", index + 1, j.name);
  const double lo = to_user(j, j.lower), hi = to_user(j, j.upper);
  const double v = io::parse_number(text, what, {lo, hi, user_unit(j)});
  return std::clamp(from_user(j, v), j.lower, j.upper);  // the round trip may pass a limit
}

TeachCommand pendant_command(const std::vector<std::string_view>& w, const kin::RobotModel& model) {
  using Kind = TeachCommand::Kind;
  TeachCommand c;
  const std::string_view word = w[0];
  constexpr const char* kUsage = "J+ J- (joint J), x+ y- z+ (move), rx+ ry- rz+ (turn), s V, q";
  if (word == "q") {
    io::expect_words(w, 1, "q");
    c.kind = Kind::leave_pendant;
    return c;
  }
  if (word == "e" || word == "?") {
    io::expect_words(w, 1, word);
    c.kind = word == "e" ? Kind::exit : Kind::menu;
    return c;
  }
  if (word == "s") {
    io::expect_words(w, 2, "s V, the step in deg or mm, e.g. s 2");
    c.kind = Kind::set_step;
    c.value = io::parse_number(w[1], "s: the step", {1e-3, kMaxTeachStep, "deg or mm"});
    return c;
  }
  const char sign = word.back();
  if (word.size() < 2 || (sign != '+' && sign != '-')) {
    throw io::ParseError(
        fmt::format("pendant: {} is not a pendant command; write {}", io::quoted(word), kUsage));
  }
  io::expect_words(w, 1, kUsage);
  c.sign = sign == '+' ? 1 : -1;
  const std::string_view axis = word.substr(0, word.size() - 1);
  if (std::isdigit(static_cast<unsigned char>(axis[0])) != 0) {
    c.kind = Kind::jog_joint;
    c.joint = io::parse_joint(axis, "pendant: the joint", model.dof());
    return c;
  }
  const std::string_view names[] = {"x", "y", "z"};
  for (std::size_t i = 0; i < 3; ++i) {
    if (axis == names[i] || (axis.size() == 2 && axis[0] == 'r' && axis.substr(1) == names[i])) {
      c.kind = axis.size() == 1 ? Kind::jog_tool : Kind::turn_tool;
      c.axis = i;
      return c;
    }
  }
  throw io::ParseError(
      fmt::format("pendant: {} is not a pendant command; write {}", io::quoted(word), kUsage));
}

}  // namespace

TeachCommand parse_teach_command(std::string_view line, const kin::RobotModel& model,
                                 bool pendant_mode) {
  using Kind = TeachCommand::Kind;
  const std::vector<std::string_view> w = io::words_of(line);
  TeachCommand c;
  if (w.empty()) return c;
  if (pendant_mode) return pendant_command(w, model);
  const std::string_view word = w[0];
  struct Plain {
    std::string_view word;
    Kind kind;
  };
  static constexpr Plain kPlain[] = {{"e", Kind::exit},
                                     {"?", Kind::menu},
                                     {"Z", Kind::zero_gravity_on},
                                     {"z", Kind::zero_gravity_off},
                                     {"p", Kind::pendant},
                                     {"xd", Kind::examine_deg},
                                     {"xr", Kind::examine_rad},
                                     {"xR", Kind::examine_range},
                                     {"h", Kind::hand_open},
                                     {"H", Kind::hand_close}};
  for (const Plain& p : kPlain) {
    if (word == p.word) {
      io::expect_words(w, 1, p.word);
      c.kind = p.kind;
      return c;
    }
  }
  if (word == "push") {
    io::expect_words(w, 4, "push J EFFORT SECONDS, e.g. push 1 5 0.5 (N m or N, s)");
    c.kind = Kind::push;
    c.joint = io::parse_joint(w[1], "push: the joint", model.dof());
    c.value =
        io::parse_number(w[2], "push: the effort", {-kMaxPushEffort, kMaxPushEffort, "N m or N"});
    c.seconds = io::parse_seconds(w[3], "push: the time", 1e-3, kMaxPushSeconds);
    return c;
  }
  if (word == "m") {
    io::expect_words(w, 3, "m J VALUE, e.g. m 1 30 (deg, or mm)");
    c.kind = Kind::move_joint;
    c.joint = io::parse_joint(w[1], "m: the joint", model.dof());
    c.value = joint_goal(w[2], model.joints[c.joint], c.joint);
    return c;
  }
  if (word == "X") {
    io::expect_words(w, 2, "X J, e.g. X 2");
    c.kind = Kind::motor_parameters;
    c.joint = io::parse_joint(w[1], "X: the joint", model.dof());
    return c;
  }
  if (word == "save") {
    io::expect_words(w, 2, "save NAME, e.g. save PICK");
    c.kind = Kind::save;
    io::check_name(w[1], "save: the name", kMaxTransformName);
    c.name = std::string(w[1]);
    return c;
  }
  throw io::ParseError(fmt::format("unknown command {}; ? lists the commands", io::quoted(word)));
}

namespace {

/// A command that cannot be done: the loop says why and counts it.
class Refused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Loop {
 public:
  Loop(Manipulator& arm, TeachIo& io)
      : arm_(arm), io_(io), model_(arm.kinematics().model()), stops_(io::stop_count()) {}

  Taught run() {
    arm_.waitfor(arm_.completed());  // the program's motions end first
    say("{}", kMenu);
    std::string line;
    std::string too_long;  // a line refused by its length
    while (!stopped() && prompt(pendant_ ? "pendant> " : "teach> ") &&
           io::read_line(io_.in, line, too_long)) {
      try {
        if (!too_long.empty()) throw io::ParseError(too_long);
        const TeachCommand c = parse_teach_command(line, model_, pendant_);
        if (c.kind == TeachCommand::Kind::exit) return finish(true);
        execute(c);
      } catch (const std::exception& e) {  // a bad command changes nothing; say why
        ++failed_;
        say("  error: {}\n", e.what());
      }
      note_termination();
    }
    if (stopped()) say("\n  stopped by a signal\n");
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

  [[nodiscard]] bool stopped() const noexcept { return io::stop_count() != stops_; }

  /// Control has ended (fault, limit, Ctrl-C): the end as the session tells it.
  [[nodiscard]] rtc::Termination ended() const { return arm_.session().termination(); }

  std::string ended_text(const rtc::Termination& t) const {
    std::string s = fmt::format("{}: {}", rtc::to_string(t.code), rtc::describe(t.code));
    if (t.joint > 0) s += fmt::format(", joint {}", t.joint);
    if (!t.detail_view().empty()) s += fmt::format(" ({})", t.detail_view());
    return s;
  }

  /// Says at once, and once, that control has ended and why.
  void note_termination() {
    const rtc::Termination t = ended();
    if (!t.ended() || told_end_) return;
    told_end_ = true;
    say("  control has ended ({}) at t = {:.3f} s: motion commands are refused; e exits\n",
        ended_text(t), t.time_s);
  }

  /// Throws unless control still runs.
  void need_control() const {
    const rtc::Termination t = ended();
    if (t.ended()) {
      throw Refused(fmt::format("control has ended ({}): motion commands are refused; e exits",
                                ended_text(t)));
    }
  }

  [[nodiscard]] kin::JointVector q() const { return arm_.session().how().q(); }

  Taught finish(bool by_exit) {
    Taught t;
    t.termination = ended();
    if (!t.termination.ended()) {
      try {
        if (arm_.zero_gravity()) arm_.set_zero_gravity(false);
      } catch (const std::exception& e) {
        ++failed_;
        say("  error: {}\n", e.what());
      }
      arm_.session().wait_for(3 * arm_.session().period());
      t.termination = ended();
    }
    t.q = q();
    t.t6 = arm_.kinematics().forward(t.q);
    t.ended_by_exit = by_exit;
    t.failed_commands = failed_;
    t.stopped_by_signal = stopped();
    return t;
  }

  void go(const PositionPtr& p, Mode mode) {
    need_control();
    if (arm_.zero_gravity()) throw Refused("zero gravity is on: `z` first");
    const Mode before = arm_.settings().mode;
    arm_.set_mode(mode);
    Motion m;
    try {
      m = arm_.move(p);  // MotionError says why it cannot
    } catch (...) {
      arm_.set_mode(before);
      throw;
    }
    arm_.set_mode(before);
    const WaitResult r = arm_.waitfor(m.end());
    if (r != WaitResult::reached) {
      if (ended().ended()) throw Refused("the motion did not end: control has ended");
      if (stopped()) throw Refused("the motion did not end: stopped by a signal");
      throw Refused(fmt::format(
          "the motion did not end ({}): {}", to_string(r),
          arm_.failures().empty() ? "no reason given" : arm_.failures().back().message()));
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

  /// Joint `j` (0-based) jogged by `step` (deg or mm): refused when it would leave its limits.
  void jog_joint(std::size_t j, double step) {
    need_control();
    const kin::Joint& J = model_.joints[j];
    const double now = q()[j];
    const double goal = now + from_user(J, step);
    if (goal < J.lower || goal > J.upper) {
      const bool up = goal > J.upper;
      throw Refused(fmt::format(
          "joint {} would go to {:.3f} {}, beyond its {} limit {:.3f} {}; jog the other way or "
          "set a smaller step (s V)",
          j + 1, to_user(J, goal), user_unit(J), up ? "upper" : "lower",
          to_user(J, up ? J.upper : J.lower), user_unit(J)));
    }
    move_joint(j, goal);
  }

  void examine(TeachCommand::Kind how) {
    const rtc::How h = arm_.session().how();
    std::string line;
    for (std::size_t j = 0; j < model_.dof(); ++j) {
      const kin::Joint& J = model_.joints[j];
      const double v = h.joint[j].q;
      if (how == TeachCommand::Kind::examine_deg) {
        line += fmt::format(" {:.3f}{}", to_user(J, v), user_unit(J));
      } else if (how == TeachCommand::Kind::examine_rad) {
        line += fmt::format(" {:.6f}{}", v, prismatic(J) ? "m" : "rad");
      } else {
        line += fmt::format(" {:.6f}", h.joint[j].range);
      }
    }
    const math::Transform t = arm_.kinematics().forward(h.q());
    say("  joints{}\n  T6 p = ({:.3f}, {:.3f}, {:.3f}) mm, a = ({:.4f}, {:.4f}, {:.4f})\n", line,
        t.p.x * 1e3, t.p.y * 1e3, t.p.z * 1e3, t.R.a.x, t.R.a.y, t.R.a.z);
  }

  void save(const std::string& name) {
    if (io_.db == nullptr && !io_.open_db) {
      throw Refused("save: no position database (--db FILE)");
    }
    const kin::JointVector now = q();
    for (std::size_t j = 0; j < model_.dof(); ++j) {
      const kin::Joint& J = model_.joints[j];
      if (!std::isfinite(now[j]) || now[j] < J.lower || now[j] > J.upper) {
        const bool up = !(now[j] < J.lower);
        throw Refused(fmt::format(
            "save: joint {} stands at {:.3f} {}, beyond its {} limit {:.3f} {}; nothing saved",
            j + 1, to_user(J, now[j]), user_unit(J), up ? "upper" : "lower",
            to_user(J, up ? J.upper : J.lower), user_unit(J)));
      }
    }
    StoredTransform t;
    t.robot = model_.name;
    t.name = name;
    t.value = arm_.kinematics().forward(now);
    t.note = "taught";
    PositionDb::check(t);  // a bad name creates no file
    if (io_.db == nullptr) io_.db = &io_.open_db();
    io_.db->put(t);
    say("  saved {} for {} in {}\n", name, model_.name, io_.db->path().string());
  }

  void execute(const TeachCommand& c) {
    using Kind = TeachCommand::Kind;
    switch (c.kind) {
      case Kind::none:
      case Kind::exit:
        return;
      case Kind::menu:
        say("{}", kMenu);
        return;
      case Kind::zero_gravity_on:
      case Kind::zero_gravity_off: {
        need_control();
        const bool on = c.kind == Kind::zero_gravity_on;
        arm_.set_zero_gravity(on);
        arm_.session().wait_for(2 * arm_.session().period());
        need_control();
        say("  zero gravity {}\n", on ? "on: push the arm" : "off: the arm holds");
        return;
      }
      case Kind::push: {
        need_control();
        if (!io_.push) throw Refused("push: this robot cannot be pushed by a simulated hand");
        io_.push(c.joint, c.value);
        // Ends early on a stop signal or when control ends.
        arm_.session().wait_for(std::chrono::duration_cast<std::chrono::nanoseconds>(
            std::chrono::duration<double>(c.seconds)));
        io_.push(c.joint, 0.0);
        if (!stopped()) arm_.session().wait_for(200ms);
        return;
      }
      case Kind::move_joint:
        move_joint(c.joint, c.value);
        return;
      case Kind::pendant:
        pendant_ = true;
        say("  pendant: J+ / J- jog joint J by {} deg or mm; x+ ... z- move, rx+ ... rz- turn "
            "the tool; s V sets the step; q leaves\n",
            step_);
        return;
      case Kind::examine_deg:
      case Kind::examine_rad:
      case Kind::examine_range:
        examine(c.kind);
        return;
      case Kind::motor_parameters: {
        need_control();
        arm_.send_setting({rtc::Setting::examine, static_cast<std::uint8_t>(c.joint), 0});
        arm_.session().wait_for(4 * arm_.session().period());
        const rtc::How h = arm_.session().how();
        if (h.examined_joint != static_cast<std::int8_t>(c.joint)) {
          need_control();
          throw Refused("X: this robot's controllers have no motor parameters to show");
        }
        std::string values;
        for (const std::uint8_t v : h.motor_parameters) values += fmt::format(" {}", v);
        say("  joint {} motor parameters:{}\n", c.joint + 1, values);
        return;
      }
      case Kind::hand_open:
      case Kind::hand_close: {
        need_control();
        const bool closed = c.kind == Kind::hand_close;
        arm_.set_hand(closed);
        arm_.session().wait_for(3 * arm_.session().period());
        need_control();
        say("  hand {}\n", closed ? "closed" : "open");
        return;
      }
      case Kind::save:
        save(c.name);
        return;
      case Kind::leave_pendant:
        pendant_ = false;
        return;
      case Kind::set_step:
        step_ = c.value;
        say("  step {}\n", step_);
        return;
      case Kind::jog_joint:
        jog_joint(c.joint, c.sign * step_);
        return;
      case Kind::jog_tool:
      case Kind::turn_tool: {
        need_control();
        math::Vec3 unit{0, 0, 0};
        (c.axis == 0 ? unit.x : c.axis == 1 ? unit.y : unit.z) = 1.0;
        const double s = c.sign * step_;
        if (c.kind == Kind::jog_tool) {
          move_tool({math::Rot3{}, unit * (s * 1e-3)});
        } else {
          move_tool({math::Rot3::about(unit, math::deg_to_rad(s)), {}});
        }
        return;
      }
    }
  }

  Manipulator& arm_;
  TeachIo& io_;
  const kin::RobotModel& model_;
  std::uint32_t stops_;  ///< io::stop_count() at the start: a change ends the loop
  bool pendant_ = false;
  bool told_end_ = false;
  std::size_t failed_ = 0;
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
