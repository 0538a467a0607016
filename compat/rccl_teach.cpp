// The positions of rccl.h and what is solved for them: makeposition (the equation read and
// checked), update (a transform from the measured T6), teach (from the arm moved by hand, with
// the position database of RCCX_DB), getcontact and updatecontact (from a guarded motion's
// contact).
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "compat_internal.hpp"
#include "compat_shared.hpp"
#include "rccx/rccl/position_db.hpp"
#include "rccx/rccl/teach.hpp"

namespace rccx::compat {

PositionBox* position_of(POS_PTR p, const char* call) {
  State& s = state();
  if (p == nullptr) {
    fail(RTC_E_ARGUMENT, fmt::format("{}(NULL): no position (did makeposition fail?)", call),
         Say::print);
    return nullptr;
  }
  const auto it = s.positions.find(p);
  if (it == s.positions.end()) {
    fail(RTC_E_ARGUMENT,
         fmt::format("{}: {} is not a position made by makeposition() (or park)", call,
                     static_cast<const void*>(p)),
         Say::print);
    return nullptr;
  }
  return it->second.get();
}

namespace {

/// The separated arguments of makeposition, read before anything can throw.
struct EquationArgs {
  static constexpr std::size_t kMax = 64;
  std::array<TRSF_PTR, kMax> t{};
  std::size_t count = 0;
  std::size_t eq = 0, tl = 0;  ///< indices of EQ and TL in t
  std::string_view problem;    ///< why reading stopped early
};

/// Reads up to the transform after TL. Stops at a NULL, an unknown pointer (it is not
/// dereferenced), EQ twice, TL before EQ or twice: what follows may not be arguments at all.
void read_equation(std::va_list ap, EquationArgs& a) noexcept {
  enum { left, right, tool } part = left;
  for (;;) {
    if (a.count == EquationArgs::kMax) {
      a.problem = "more than 64 arguments: is EQ or TL missing?";
      return;
    }
    TRSF_PTR t = va_arg(ap, TRSF_PTR);
    a.t[a.count++] = t;
    if (t == nullptr) {
      a.problem = "a NULL transform (did newtrans or gentr_ fail?)";
      return;
    }
    if (t == rccl_EQ) {
      if (part != left) {
        a.problem = part == right ? "EQ twice" : "EQ after TL";
        return;
      }
      a.eq = a.count - 1;
      part = right;
      continue;
    }
    if (t == rccl_TL) {
      if (part != right) {
        a.problem = part == left ? "TL before EQ" : "TL twice";
        return;
      }
      a.tl = a.count - 1;
      part = tool;
      continue;
    }
    if (box_of(t) == nullptr) {
      a.problem = "a pointer that is not a transform made by newtrans or gentr_ (or t6)";
      return;
    }
    if (part == tool) return;
  }
}

/// The transform `trans` that update() or teach() solves `box`'s equation for (`what`: "solve
/// for", "teach"), or null with the error printed: one of the equation's own, not t6.
TrsfBox* unknown_in(const char* call, const char* what, TRSF_PTR trans, const PositionBox& box) {
  TrsfBox* x = box_of(trans);
  if (x == nullptr || x == &t6_box()) {
    fail(RTC_E_ARGUMENT,
         fmt::format("{}(..., {}): the transform to {} must be one of the equation's, made by "
                     "newtrans or gentr_, not t6",
                     call, box.name, what),
         Say::print);
    return nullptr;
  }
  return x;
}

/// `box`'s position with the unknown `x` (the box of `trans`) as a hold of its present value,
/// returned in `xt`; null with the error printed when `x` is not in the equation.
rc::PositionPtr equation_for(const char* call, TRSF_PTR trans, const TrsfBox& x,
                             const PositionBox& box, rc::TransformPtr& xt) {
  const rc::PositionPtr p = build_position(box, math::Transform::identity(), trans, &xt);
  if (!xt) {
    fail(RTC_E_ARGUMENT,
         fmt::format("{}({}, {}): {} is not in the equation {}", call, x.name, box.name, x.name,
                     p->describe()),
         Say::print);
    return nullptr;
  }
  return p;
}

/// update() and updatecontact(): trans solved for pos's equation with T6 = `t6`, or the
/// measured T6 when there is none.
TRSF_PTR solve_update(const char* call, TRSF_PTR trans, POS_PTR pos,
                      const std::optional<math::Transform>& t6) {
  TRSF_PTR out = nullptr;
  guarded(call, Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    PositionBox* box = position_of(pos, call);
    if (box == nullptr) return rtc_error;
    const TrsfBox* x = unknown_in(call, "solve for", trans, *box);
    if (x == nullptr) return rtc_error;
    if (!s.arm_session) {
      return fail(RTC_E_SEQUENCE,
                  fmt::format("{}: call rccl_open() first (T6 is read from the arm)", call),
                  Say::print);
    }
    rc::TransformPtr xt;
    const rc::PositionPtr p = equation_for(call, trans, *x, *box, xt);
    if (!p) return rtc_error;
    to_c(p->solve_for(*xt, t6 ? *t6 : measured_t6(*s.arm_session)), *trans);
    out = trans;
    return RTC_OK;
  });
  return out;
}

/// The contact of the last motion to `box` that ended, if its guard tripped.
std::optional<rc::Contact> last_contact(const State& s, const PositionBox* box) {
  if (!s.arm_session) return std::nullopt;
  const ArmSession& a = *s.arm_session;
  for (auto it = a.motion_boxes.rbegin(); it != a.motion_boxes.rend(); ++it) {
    if (it->second != box) continue;
    const rc::Motion m{it->first};
    if (!a.arm.happened(m.end())) continue;
    return a.arm.contact(m);
  }
  return std::nullopt;
}

/// teach()'s position database: RCCX_DB, else rccx.db in the working directory.
std::string teach_db_file() {
  const char* env = std::getenv("RCCX_DB");
  return env != nullptr && env[0] != '\0' ? env : "rccx.db";
}

/// The database `file` opened for teaching `transform`, or null with the error printed.
std::unique_ptr<rc::PositionDb> open_teach_db(const std::string& transform,
                                              const std::string& file) {
  try {
    return std::make_unique<rc::PositionDb>(file);
  } catch (const rc::DatabaseError& e) {
    fail(RTC_E_OPEN,
         fmt::format("teach({}): the position database {} cannot be used: {}; set RCCX_DB to a "
                     "database file you can write",
                     transform, file, e.what()),
         Say::print);
    return nullptr;
  }
}

/// Teach mode on the terminal (rc::teach_loop): the arm moved by hand until `exit`. The arm's T6
/// then, or nothing (said on stdout) when teaching ended otherwise.
std::optional<math::Transform> teach_by_hand(ArmSession& a, rc::PositionDb& db,
                                             const std::string& transform,
                                             const std::string& position) {
  std::printf("teach mode V1.0, transform %s, position %s\n", transform.c_str(), position.c_str());
  std::fflush(stdout);
  rc::TeachIo io{std::cin, std::cout, &db, {}};
  io.push = [&a](std::size_t joint, double effort) { a.robot.push(joint, effort); };
  const rc::Taught taught = rc::teach_loop(a.arm, io);
  report_failures(a);
  refresh();
  if (!taught.ended_by_exit || taught.termination.ended() || taught.stopped_by_signal) {
    std::printf("teach: nothing taught for %s\n", transform.c_str());
    return std::nullopt;
  }
  return taught.t6;
}

}  // namespace

}  // namespace rccx::compat

using namespace rccx::compat;

extern "C" {

POS_PTR makeposition(const char* name, ...) {
  EquationArgs a;
  std::va_list ap;
  va_start(ap, name);
  read_equation(ap, a);
  va_end(ap);

  POS_PTR out = nullptr;
  guarded("makeposition", Say::print, RTC_E_EQUATION, [&] {
    const std::string n = name != nullptr ? name : "?";
    if (!a.problem.empty()) {
      return fail(RTC_E_EQUATION,
                  fmt::format("makeposition({}): argument {} after the name: {}; write "
                              "makeposition(name, left side (t6 among it), EQ, right side, "
                              "TL, tool), e.g. makeposition(\"P1\", t6, EQ, b, TL, t6)",
                              n, a.count, a.problem),
                  Say::print);
    }
    auto box = std::make_unique<PositionBox>();
    box->name = n;
    for (std::size_t i = 0; i < a.eq; ++i) box->lhs.push_back(a.t[i]);
    for (std::size_t i = a.eq + 1; i < a.tl; ++i) box->rhs.push_back(a.t[i]);
    box->tool = a.t[a.tl + 1];
    // Built once now so that a malformed equation is refused here (the values are checked at
    // each move(): they may change until then).
    std::vector<rc::TransformPtr> lhs, rhs;
    rc::TransformPtr tool;
    const auto stand_in = [](TRSF* t) {
      TrsfBox* b = box_of(t);
      return b == &t6_box() ? rc::t6() : rc::constant(b->name, math::Transform::identity());
    };
    for (TRSF* t : box->lhs) {
      lhs.push_back(stand_in(t));
      if (t == box->tool) tool = lhs.back();
    }
    for (TRSF* t : box->rhs) rhs.push_back(stand_in(t));
    if (!tool && box->tool != nullptr) {
      return fail(RTC_E_EQUATION,
                  fmt::format("makeposition({}): the tool transform after TL ({}) must be one of "
                              "the left side's, at or after t6 (t6 itself for no tool)",
                              n, box_of(box->tool)->name),
                  Say::print);
    }
    (void)rc::Position::make(n, lhs, rhs, tool);  // throws EquationError saying what is wrong
    box->c.name = box->name.c_str();
    POS_PTR p = &box->c;
    state().positions.emplace(p, std::move(box));
    out = p;
    return RTC_OK;
  });
  return out;
}

TRSF_PTR update(TRSF_PTR trans, POS_PTR pos) {
  return solve_update("update", trans, pos, std::nullopt);
}

int teach(TRSF_PTR trans, POS_PTR pos) {
  int answer = NO;
  guarded("teach", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    PositionBox* box = position_of(pos, "teach");
    if (box == nullptr) return rtc_error;
    const TrsfBox* x = unknown_in("teach", "teach", trans, *box);
    if (x == nullptr) return rtc_error;
    if (const int c = check_can_move(s, "teach(" + x->name + ")"); c != RTC_OK) return c;
    rc::TransformPtr xt;
    const rc::PositionPtr p = equation_for("teach", trans, *x, *box, xt);
    if (!p) return rtc_error;
    const std::string file = teach_db_file();
    const std::unique_ptr<rc::PositionDb> opened = open_teach_db(x->name, file);
    if (!opened) return rtc_error;
    rc::PositionDb& db = *opened;
    ArmSession& a = *s.arm_session;
    const std::string& robot = a.arm.kinematics().model().name;
    if (const auto stored = db.get(robot, x->name)) {
      to_c(stored->value, *trans);
      std::printf("teach: %s taken from the position database %s\n", x->name.c_str(), file.c_str());
      answer = YES;
      return RTC_OK;
    }
    const std::optional<math::Transform> t6_taught = teach_by_hand(a, db, x->name, box->name);
    if (!t6_taught) return RTC_OK;
    const math::Transform value = p->solve_for(*xt, *t6_taught);
    rc::StoredTransform st;
    st.robot = robot;
    st.name = x->name;
    st.value = value;
    st.note = "taught for " + box->name;
    db.put(st);
    to_c(value, *trans);
    answer = YES;
    return RTC_OK;
  });
  return answer;
}

int getcontact(POS_PTR pos, TRSF_PTR at) {
  int answer = NO;
  guarded("getcontact", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    PositionBox* box = position_of(pos, "getcontact");
    if (box == nullptr) return rtc_error;
    const std::optional<rc::Contact> c = last_contact(s, box);
    if (!c) return RTC_OK;
    if (at != nullptr) to_c(c->tool_frame, *at);
    answer = YES;
    return RTC_OK;
  });
  return answer;
}

TRSF_PTR updatecontact(TRSF_PTR trans, POS_PTR pos) {
  State& s = state();
  PositionBox* box = position_of(pos, "updatecontact");
  if (box == nullptr) return nullptr;
  const std::optional<rc::Contact> c = last_contact(s, box);
  if (!c) {
    fail(RTC_E_SEQUENCE,
         fmt::format("updatecontact(..., {}): the last motion to {} made no contact (set a "
                     "limit() before it, and waitfor its end)",
                     box->name, box->name),
         Say::print);
    return nullptr;
  }
  return solve_update("updatecontact", trans, pos, c->t6);
}

}  // extern "C"
