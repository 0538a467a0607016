// The motion calls of rccl.h for the one arm of rccl_open: the settings (setvel, setmod,
// settime, setconf; comply, lock, limit, setload), move, stop, distance, and waitfor's sample
// (rccl_wait_sample), with nextmove. Each move() builds its position from the transforms'
// values then (build_position) and applies the settings; rccl_close() tells of the refused ones.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "rccx/net/remote_cell.hpp"
// rccx's headers before the C ones (compat_internal.hpp)
#include "compat_internal.hpp"
#include "compat_shared.hpp"

namespace rccx::compat {

namespace {

/// The letters setconf("...") asks for, in the order written: words (lefty, up, noflip, ...)
/// as their letter, other words letter by letter ("lun"), lower case.
std::string asked_letters(std::string_view asked) {
  // Each word or letter is one choice: l r (shoulder), u d (elbow), n f (wrist).
  static constexpr std::array<std::pair<std::string_view, char>, 14> kWords{{
      {"lefty", 'l'},
      {"left", 'l'},
      {"righty", 'r'},
      {"right", 'r'},
      {"up", 'u'},
      {"above", 'u'},
      {"down", 'd'},
      {"below", 'd'},
      {"noflip", 'n'},
      {"flip", 'f'},
      {"l", 'l'},
      {"r", 'r'},
      {"n", 'n'},
      {"f", 'f'},
  }};
  std::string letters;
  std::string word;
  const auto take = [&](std::string_view w) {
    if (w.empty()) return;
    for (const auto& [name, letter] : kWords) {
      if (w == name) {
        letters += letter;
        return;
      }
    }
    for (const char c : w) letters += c;  // "lun", "ud": letters run together
  };
  for (const char c : asked) {
    if (c == ' ' || c == ',' || c == '-' || c == '_') {
      take(word);
      word.clear();
    } else {
      word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  take(word);
  return letters;
}

/// The configuration `asked` (letters or words) in the robot's names, letters not given taken
/// from `present`. Throws std::invalid_argument naming the robot's letters.
std::string configuration_letters(const kin::Kinematics& k, std::string_view asked,
                                  std::string_view present) {
  const std::string letters = asked_letters(asked);
  std::string out(present);
  const auto names = k.configuration_names();
  for (const char c : letters) {
    bool placed = false;
    for (std::size_t i = 0; i < out.size() && !placed; ++i) {
      // Position i takes the letters that the robot's names use there.
      for (const std::string_view n : names) {
        if (i < n.size() && n[i] == c) {
          out[i] = c;
          placed = true;
          break;
        }
      }
    }
    if (!placed) {
      std::string known;
      for (const std::string_view n : names)
        known += fmt::format("{}{}", known.empty() ? "" : ", ", n);
      throw std::invalid_argument(fmt::format(
          "setconf(\"{}\"): robot {} has no configuration letter '{}'; its configurations are "
          "{} (l/r shoulder lefty/righty, u/d elbow up/down, n/f wrist noflip/flip)",
          asked, k.model().name, c, known.empty() ? "none" : known));
    }
  }
  return out;
}

/// The robot's name of the configuration the arm is in now.
std::string present_configuration(const ArmSession& a) {
  const kin::Kinematics& k = a.arm.kinematics();
  return std::string(k.configuration_names()[k.configuration_of(a.robot.session->how().q()).index]);
}

/// Settings, configuration and the queue's bookkeeping for one move() or stop().
void apply_settings(ArmSession& a, const rc::MotionSettings& settings) {
  a.arm.set_mode(settings.mode);
  a.arm.set_velocity(settings.translation_m_per_s, settings.rotation_rad_per_s);
  a.arm.set_segment_time(settings.segment_time_s);
  a.arm.set_transition_time(settings.transition_time_s);
  a.arm.set_guard(settings.guard);
  a.arm.set_compliance(settings.compliance);
  // setconf() is for joint moves, which may change configuration; a Cartesian line keeps the
  // arm's (the manual's setconf letters stay asked for the joint moves that follow).
  if (a.configuration.empty() || settings.mode == rc::Mode::cartesian) {
    a.arm.set_configuration("");
  } else {
    a.arm.set_configuration(
        configuration_letters(a.arm.kinematics(), a.configuration, present_configuration(a)));
  }
}

/// A 1986 program does not look at move()'s result: rccl_close() will tell.
void note_refusal(int code) noexcept {
  State& s = state();
  if (s.arm_session) s.arm_session->refusals.note(code);
}

/// The result of a C transform's function, the planning side: `nextmove` set by the program.
/// `in_loop`: called from the sample loop, where a remote arm's request (a round trip) must
/// not be made; a remote cell has no local loop that runs C functions, so none is lost.
void act_on_nextmove(State& s, bool in_loop) noexcept {
  if (s.arm_session) s.arm_session->arm.generator().request_next();
  if (s.cell_session) {
    for (const auto& [name, m] : s.cell_session->manips) {
      if (m->local != nullptr) {
        m->local->generator().request_next();
      } else if (m->remote != nullptr && !in_loop) {
        (void)guarded("nextmove", Say::print, RTC_E_MOTION, [&] {
          m->remote->nextmove();
          return RTC_OK;
        });
      }
    }
  }
}

/// The words of `what` (fx fy fz tx ty tz, and `extra` when given) with the value that follows
/// each among the arguments: what comply() and limit() read. Throws std::invalid_argument.
std::vector<std::pair<std::size_t, double>> force_words(const char* call, const std::string& text,
                                                        const std::array<double, 16>& values,
                                                        bool with_values) {
  std::vector<std::pair<std::size_t, double>> out;
  std::size_t k = 0;
  const auto take = [&](const std::string& w) {
    if (w.empty()) return;
    std::size_t axis = 6;  // "f": the force's magnitude (limit only)
    const auto it = std::find(rc::kForceAxisNames.begin(), rc::kForceAxisNames.end(), w);
    if (it != rc::kForceAxisNames.end()) {
      axis = static_cast<std::size_t>(it - rc::kForceAxisNames.begin());
    } else if (!(w == "f" && std::string_view(call) == "limit")) {
      throw std::invalid_argument(fmt::format(
          "{}(\"{}\"): unknown axis \"{}\"; the words are fx fy fz (N) and tx ty tz (N m) of "
          "the tool frame{}",
          call, text, w,
          std::string_view(call) == "limit" ? ", or f (the force's magnitude)" : ""));
    }
    double v = 0.0;
    if (with_values) {
      if (k >= values.size()) throw std::invalid_argument(fmt::format("{}: too many words", call));
      v = values[k++];
      if (!std::isfinite(v)) {
        throw std::invalid_argument(
            fmt::format("{}(\"{}\"): the value of {} is not finite", call, text, w));
      }
    }
    out.emplace_back(axis, v);
  };
  for_each_word(text, take);
  if (out.empty()) {
    throw std::invalid_argument(
        fmt::format("{}: no axis given; e.g. {}(\"fz\"{})", call, call, with_values ? ", 5." : ""));
  }
  return out;
}

/// The doubles that follow a word string among a call's arguments: one per word.
struct WordValues {
  std::array<double, 16> values{};
  std::size_t count = 0;  ///< words read (values.size() at most)
};

/// Reads one double per word of `what` (before anything can throw): distance(), comply() and
/// limit().
WordValues word_values(const char* what, std::va_list ap) {
  WordValues out;
  bool in_word = false;
  for (const char* c = what; c != nullptr && *c != '\0'; ++c) {
    const bool sep = *c == ' ' || *c == ',' || *c == '\t';
    if (!sep && !in_word && out.count < out.values.size()) {
      out.values[out.count++] = va_arg(ap, double);
    }
    in_word = !sep;
  }
  return out;
}

/// The displacement the words of distance("...") ask for in the tool frame: dx dy dz (mm) and
/// rx ry rz (deg, composed in the order written), each with its value from `values`; `given`
/// counts the words taken. Throws std::invalid_argument.
math::Transform displacement_of(const std::string& text, const std::array<double, 16>& values,
                                std::size_t& given) {
  math::Transform trans = math::Transform::identity();
  math::Rot3 rotation = math::Rot3::identity();
  std::size_t& k = given;
  const auto take = [&](const std::string& w) {
    if (w.empty()) return;
    const double v = values[k++];
    if (!std::isfinite(v)) {
      throw std::invalid_argument(
          fmt::format("distance(\"{}\"): the value of {} is not finite", text, w));
    }
    if (w == "dx")
      trans.p.x += v * 1e-3;
    else if (w == "dy")
      trans.p.y += v * 1e-3;
    else if (w == "dz")
      trans.p.z += v * 1e-3;
    else if (w == "rx")
      rotation = rotation * math::Rot3::rot_x(v * std::numbers::pi / 180.0);
    else if (w == "ry")
      rotation = rotation * math::Rot3::rot_y(v * std::numbers::pi / 180.0);
    else if (w == "rz")
      rotation = rotation * math::Rot3::rot_z(v * std::numbers::pi / 180.0);
    else {
      throw std::invalid_argument(fmt::format(
          "distance(\"{}\"): unknown displacement \"{}\"; the words are dx dy dz (mm) and rx "
          "ry rz (deg), each followed by its value (a double) among the arguments",
          text, w));
    }
  };
  for_each_word(text, take);
  trans.R = rotation;
  return trans;
}

}  // namespace

void take_nextmove() noexcept {
  State& s = state();
  if (nextmove != 0) {
    nextmove = 0;
    act_on_nextmove(s, false);
  }
}

void loop_nextmove() noexcept {
  if (nextmove == 0) return;
  nextmove = 0;
  // The loop is the generator's own thread: request_next() takes effect at the next step.
  act_on_nextmove(state(), true);
}

}  // namespace rccx::compat

using namespace rccx::compat;

extern "C" {

int setvel(double mm_per_s, double deg_per_s) {
  return guarded("setvel", Say::print, RTC_E_ARGUMENT, [&] {
    if (!(mm_per_s > 0.0) || !(deg_per_s > 0.0) || !finite({mm_per_s, deg_per_s})) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("setvel({}, {}): both speeds must be finite and > 0 (mm/s, deg/s)",
                              mm_per_s, deg_per_s),
                  Say::print);
    }
    State& s = state();
    s.settings.translation_m_per_s = mm_per_s * 1e-3;
    s.settings.rotation_rad_per_s = deg_per_s * (std::numbers::pi / 180.0);
    return RTC_OK;
  });
}

int setmod(int mode) {
  return guarded("setmod", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (mode == 'j' || mode == 'J') {
      s.settings.mode = rc::Mode::joint;
    } else if (mode == 'c' || mode == 'C') {
      s.settings.mode = rc::Mode::cartesian;
    } else {
      const std::string got = mode > ' ' && mode < 127
                                  ? fmt::format("'{}'", static_cast<char>(mode))
                                  : fmt::format("{}", mode);
      return fail(RTC_E_ARGUMENT,
                  fmt::format("setmod({}): the mode is 'j' (joint) or 'c' (Cartesian)", got),
                  Say::print);
    }
    return RTC_OK;
  });
}

int settime(double transition_ms, double segment_ms) {
  return guarded("settime", Say::print, RTC_E_ARGUMENT, [&] {
    if (!(transition_ms > 0.0) || !(segment_ms >= 0.0) || !finite({transition_ms, segment_ms})) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("settime({}, {}): the transition time (ms) must be > 0 and the "
                              "segment time (ms) >= 0 (0: from the speeds of setvel)",
                              transition_ms, segment_ms),
                  Say::print);
    }
    State& s = state();
    s.settings.transition_time_s = transition_ms * 1e-3;
    s.settings.segment_time_s = segment_ms * 1e-3;
    return RTC_OK;
  });
}

int setconf(const char* configuration) {
  return guarded("setconf", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const std::string asked = configuration != nullptr ? configuration : "";
    if (s.arm_session && !asked.empty()) {
      // Checked now against the robot's letters (the arm's present ones fill the rest).
      const kin::Kinematics& k = s.arm_session->arm.kinematics();
      if (k.configuration_names().empty()) {
        return fail(RTC_E_ARGUMENT,
                    fmt::format("setconf(\"{}\"): robot {} has no named configurations", asked,
                                k.model().name),
                    Say::print);
      }
      (void)configuration_letters(k, asked, present_configuration(*s.arm_session));
    }
    // Kept by the open session's arm only: rccl_open starts with none.
    if (s.arm_session) s.arm_session->configuration = asked;
    return RTC_OK;
  });
}

int move(POS_PTR p) {
  const int code = guarded("move", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    PositionBox* box = p == park ? nullptr : position_of(p, "move");
    if (p != park && box == nullptr) return rtc_error;
    const std::string name = p == park ? "park" : box->name;
    if (const int c = check_can_move(s, "move(" + name + ")"); c != RTC_OK) return c;
    ArmSession& a = *s.arm_session;
    if (p == park) box = &park_position(s, a);
    take_nextmove();
    const rc::PositionPtr target = build_position(*box, a.displacement);
    apply_settings(a, s.settings);
    const rc::Motion m = a.arm.move(target);
    a.displacement = math::Transform::identity();
    box->queued.push_back(target);
    a.motion_names[m.id] = name;
    a.motion_boxes[m.id] = box;
    refresh();
    return RTC_OK;
  });
  note_refusal(code);
  return code;
}

int stop(double ms) {
  const int code = guarded("stop", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (!(ms >= 0.0) || !std::isfinite(ms)) {
      return fail(RTC_E_ARGUMENT, fmt::format("stop({}): the time is >= 0 ms", ms), Say::print);
    }
    if (const int c = check_can_move(s, fmt::format("stop({})", ms)); c != RTC_OK) return c;
    ArmSession& a = *s.arm_session;
    apply_settings(a, s.settings);
    const rc::Motion m = a.arm.dwell(ms * 1e-3);
    a.motion_names[m.id] = fmt::format("stop {} ms", ms);
    refresh();
    return RTC_OK;
  });
  note_refusal(code);
  return code;
}

int distance(const char* what, ...) {
  std::va_list ap;
  va_start(ap, what);
  const WordValues read = word_values(what, ap);
  va_end(ap);
  return guarded("distance", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const std::string text = what != nullptr ? what : "";
    if (read.count > 15) {
      return fail(RTC_E_ARGUMENT, fmt::format("distance(\"{}\"): at most 15 displacements", text),
                  Say::print);
    }
    std::size_t given = 0;
    const math::Transform trans = displacement_of(text, read.values, given);
    if (given == 0) {
      return fail(RTC_E_ARGUMENT, "distance: no displacement given; e.g. distance(\"dz\", -30.)",
                  Say::print);
    }
    // Kept by the open session's arm only: rccl_open starts with none.
    if (s.arm_session) s.arm_session->displacement = s.arm_session->displacement * trans;
    return RTC_OK;
  });
}

int rccl_wait_sample(void) {
  return guarded("waitfor", Say::print, RTC_E_INTERNAL, [] {
    State& s = state();
    take_nextmove();
    if (s.cell_session) return cell_wait_tick();
    if (!s.arm_session || !s.arm_session->controlling) {
      return fail(RTC_E_SEQUENCE,
                  "waitfor: nothing runs to wait on; call rccl_open() and rccl_control() first",
                  Say::print);
    }
    ArmSession& a = *s.arm_session;
    rtc::Session& session = *a.robot.session;
    if (session.controlling()) session.wait_for(session.period());
    report_failures(a);
    const rtc::How how = session.how();
    rtime = std::lround(how.time_s * 1e3);
    rccl_sample = static_cast<long>(how.sample);
    to_c(a.arm.kinematics().forward(how.q()), t6_box().c);
    refresh();
    if (!session.controlling()) return control_ended(a, "waitfor");
    return RTC_OK;
  });
}

int comply(const char* what, ...) {
  std::va_list ap;
  va_start(ap, what);
  const std::array<double, 16> values = word_values(what, ap).values;
  va_end(ap);
  return guarded("comply", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    rc::Compliance c = s.settings.compliance;
    for (const auto& [axis, value] : force_words("comply", what ? what : "", values, true)) {
      c.axes = static_cast<std::uint8_t>(c.axes | (1U << axis));
      c.force[axis] = value;
    }
    try {
      rc::check_compliance(c);
    } catch (const rc::MotionError& e) {
      throw std::invalid_argument(e.what());  // a bad argument: nothing changed
    }
    s.settings.compliance = c;
    return RTC_OK;
  });
}

int lock(const char* what) {
  return guarded("lock", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const std::string text = what ? what : "";
    rc::Compliance c = s.settings.compliance;
    if (text == "all") {
      c = rc::Compliance{};
    } else {
      for (const auto& [axis, value] : force_words("lock", text, {}, false)) {
        c.axes = static_cast<std::uint8_t>(c.axes & ~(1U << axis));
        c.force[axis] = 0.0;
      }
    }
    s.settings.compliance = c;
    return RTC_OK;
  });
}

int limit(const char* what, ...) {
  std::va_list ap;
  va_start(ap, what);
  const std::array<double, 16> values = word_values(what, ap).values;
  va_end(ap);
  return guarded("limit", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const std::string text = what ? what : "";
    if (text == "off" || text.empty()) {
      s.settings.guard = rc::ForceGuard{};
      return RTC_OK;
    }
    const auto words = force_words("limit", text, values, true);
    if (words.size() != 1) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("limit(\"{}\"): one axis at a time (or f, the magnitude)", text),
                  Say::print);
    }
    rc::ForceGuard g;
    g.kind = words[0].first == 6 ? rc::ForceGuard::Kind::magnitude : rc::ForceGuard::Kind::along;
    g.axis = static_cast<std::uint8_t>(words[0].first % 6);
    g.threshold = words[0].second;
    try {
      rc::check_guard(g);
    } catch (const rc::MotionError& e) {
      throw std::invalid_argument(e.what());
    }
    s.settings.guard = g;
    return RTC_OK;
  });
}

int setload(double kg, double x, double y, double z) {
  return guarded("setload", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (!(kg >= 0.0) || !std::isfinite(kg) || !std::isfinite(x) || !std::isfinite(y) ||
        !std::isfinite(z)) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("setload({}, {}, {}, {}): the mass is >= 0 kg and the centre of "
                              "mass finite (mm in T6)",
                              kg, x, y, z),
                  Say::print);
    }
    if (!s.arm_session) {
      return fail(RTC_E_SEQUENCE, "setload: call rccl_open() first", Say::print);
    }
    rccx::force::ToolLoad load;
    load.mass_kg = kg;
    load.com_m = {x * 1e-3, y * 1e-3, z * 1e-3};
    s.arm_session->arm.set_tool_load(load);
    return RTC_OK;
  });
}

}  // extern "C"
