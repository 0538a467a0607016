// The workcell part of rccl.h (Multi-RCCL style): rccl_cell_open, a MANIP handle per robot,
// the mnp_ calls, rccl_together. Positions and transforms are shared with the one-robot calls
// (compat_internal.hpp); waitfor() lets one tick of the cell's clock run.
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "compat_internal.hpp"
#include "compat_shared.hpp"
#include "rccx/io/data_files.hpp"

namespace rccx::compat {

namespace {

/// Prints the motions of robot m that failed since the last call; true when its control has
/// ended (printed once).
bool cell_report(rccl_manip& m) {
  // POS.code of each motion's position, as move() sets it for one robot: 0 when it ended,
  // RCCL_NEXTMOVE / RCCL_ONF ended early, RTC_E_MOTION failed or cancelled (a collision stop).
  show_motion_codes(*m.arm, m.motion_boxes);
  const std::vector<rc::MotionEvent>& f = m.arm->failures();
  std::size_t cancelled = 0;
  for (; m.failures_seen < f.size(); ++m.failures_seen) {
    const rc::MotionEvent& e = f[m.failures_seen];
    const auto it = m.motion_names.find(e.id);
    const std::string what = it == m.motion_names.end()
                                 ? fmt::format("{} motion {}", m.name, e.id)
                                 : fmt::format("{} motion {} (to {})", m.name, e.id, it->second);
    if (e.kind == rc::EventKind::failed || !e.message().empty()) {
      fail(
          RTC_E_MOTION,
          fmt::format("{} {} at t = {:.3f} s: {}", what, rc::to_string(e.kind), e.t_s, e.message()),
          Say::print);
    } else {
      ++cancelled;
    }
  }
  if (cancelled > 0)
    std::fprintf(stderr, "rccl: %s: %zu queued motion(s) cancelled\n", m.name.c_str(), cancelled);
  if (m.arm->session().controlling()) return false;
  if (!m.told_ended) {
    m.told_ended = true;
    fail(RTC_E_TERMINATED,
         fmt::format("{}: {}", m.name, describe_end(m.arm->session().termination())), Say::print);
  }
  return true;
}

/// The handle `m` checked: a robot of the open cell.
rccl_manip* known(const MANIP* m) {
  const State& s = state();
  if (m == nullptr || !s.cell_session) return nullptr;
  for (const auto& [name, box] : s.cell_session->manips) {
    if (box.get() == m) return box.get();
  }
  return nullptr;
}

int bad_handle(const char* call) {
  return fail(RTC_E_ARGUMENT,
              fmt::format("{}: not a robot of the open cell (a NULL handle, or one from before "
                          "rcclRelease); get one from rcclCreate(name, 0)",
                          call),
              Say::print);
}

/// A robot's position or transform, or NULL (with the error) for a bad handle.
template <class T>
T* member_of(const MANIP* m, const char* call, T* rccl_manip::*member) {
  rccl_manip* r = known(m);
  if (r == nullptr) {
    bad_handle(call);
    return nullptr;
  }
  return r->*member;
}

}  // namespace

/// waitfor() with a cell: one tick of the cell's clock.
int cell_wait_tick() {
  CellSession& c = *state().cell_session;
  if (!c.started) {
    return fail(RTC_E_SEQUENCE, "waitfor: call rcclStart() before waiting on the cell", Say::print);
  }
  bool any = false;
  for (auto& [name, m] : c.manips) any = any || m->arm->session().controlling();
  if (any) c.cell->wait_for(c.cell->group().period());
  bool all_ended = true;
  for (auto& [name, m] : c.manips) all_ended = cell_report(*m) && all_ended;
  if (!c.manips.empty()) {
    const rtc::How how = c.manips.begin()->second->arm->session().how();
    rtime = std::lround(how.time_s * 1e3);
    rccl_sample = static_cast<long>(how.sample);
  }
  refresh();
  if (all_ended) {
    return fail(RTC_E_TERMINATED, "waitfor: every robot's control has ended; rcclRelease()",
                Say::quiet);
  }
  return RTC_OK;
}

}  // namespace rccx::compat

using namespace rccx::compat;

extern "C" {

int rccl_cell_open(const char* cell_file) {
  return guarded("rccl_cell_open", Say::quiet, RTC_E_ROBOT, [&] {
    State& s = state();
    if (s.arm_session || s.cell_session) {
      return fail(RTC_E_SEQUENCE,
                  "rccl_cell_open: a session or cell is open; rccl_close() or rcclRelease() it "
                  "first",
                  Say::quiet);
    }
    if (rtc_session_open()) {
      return fail(RTC_E_SEQUENCE,
                  "rccl_cell_open: an RTC session (control, rtc_open) is open; release() or "
                  "rtc_close() it first",
                  Say::quiet);
    }
    std::string path = cell_file != nullptr ? cell_file : "";
    if (path.empty()) {
      if (const char* env = std::getenv("RCCX_CELL"); env != nullptr) path = env;
    }
    std::unique_ptr<rccx::cell::Cell> loaded;
    try {
      // $RCCX_DATA_DIR, the source tree, the installed copy (rccx/io/data_files.hpp).
      if (path.empty()) path = rccx::io::find_data_file("cells/cvarl.json").string();
      loaded = rccx::cell::Cell::load(path);
    } catch (const rccx::io::DataFileError& e) {
      return fail(RTC_E_ROBOT, fmt::format("rccl_cell_open: {}; or set RCCX_CELL", e.what()),
                  Say::quiet);
    } catch (const rccx::cell::CellFileError& e) {
      return fail(RTC_E_ROBOT, fmt::format("rccl_cell_open: {}", e.what()), Say::quiet);
    }
    s.cell_session.emplace(std::move(loaded));
    refresh();
    return RTC_OK;
  });
}

MANIP* rcclCreate(const char* name, int /*flags*/) {
  MANIP* out = nullptr;
  guarded("rcclCreate", Say::print, RTC_E_ROBOT, [&] {
    State& s = state();
    if (!s.cell_session) {
      return fail(RTC_E_SEQUENCE, "rcclCreate: call rccl_cell_open() first", Say::print);
    }
    CellSession& c = *s.cell_session;
    const std::string n = name != nullptr ? name : "";
    if (const auto it = c.manips.find(n); it != c.manips.end()) {
      out = it->second.get();
      return RTC_OK;
    }
    auto m = std::make_unique<rccl_manip>();
    m->name = n;
    m->arm = &c.cell->robot(n);  // std::invalid_argument names the cell's robots
    m->tool = keep_transform(c.cell->tool_transform(n));
    m->base_inv = keep_transform(c.cell->base_inv_transform(n));
    m->tool_frame = keep_transform(c.cell->tool_frame(n));
    auto park_pos = std::make_unique<PositionBox>();
    park_pos->name = n + " park";
    park_pos->joints = m->arm->park();
    park_pos->c.name = park_pos->name.c_str();
    m->park = &park_pos->c;
    s.positions.emplace(m->park, std::move(park_pos));
    out = m.get();
    c.manips.emplace(n, std::move(m));
    return RTC_OK;
  });
  return out;
}

int rcclStart(void) {
  return guarded("rcclStart", Say::quiet, RTC_E_INTERNAL, [] {
    State& s = state();
    if (!s.cell_session) {
      return fail(RTC_E_SEQUENCE, "rcclStart: call rccl_cell_open() first", Say::quiet);
    }
    CellSession& c = *s.cell_session;
    if (c.started) return fail(RTC_E_SEQUENCE, "rcclStart: the cell runs already", Say::quiet);
    c.cell->start();
    c.started = true;
    refresh();
    return RTC_OK;
  });
}

int rcclRelease(int power_off) {
  return guarded("rcclRelease", Say::quiet, RTC_E_INTERNAL, [&] {
    State& s = state();
    if (!s.cell_session) return fail(RTC_E_SEQUENCE, "rcclRelease: no cell is open", Say::quiet);
    // Whatever happens below, the cell is gone afterwards.
    struct Closer {
      State& s;
      ~Closer() {
        s.cell_session.reset();
        for (auto& [key, box] : s.positions) box->queued.clear();
        refresh();
      }
    } closer{s};
    CellSession& c = *s.cell_session;
    int code = RTC_OK;
    std::string why;
    for (auto& [name, m] : c.manips) {
      if (c.started) cell_report(*m);
      const rtc::Termination t =
          c.started ? m->arm->stop_control() : m->arm->session().termination();
      if (code != RTC_OK) continue;
      const std::vector<rc::MotionEvent>& failures = m->arm->failures();
      if (t.ended()) {
        code = RTC_E_TERMINATED;
        why = fmt::format("{}: {}", name, describe_end(t));
      } else if (!failures.empty()) {
        code = RTC_E_MOTION;
        why = fmt::format("{}: {} motion(s) failed or were cancelled; first motion {} {}: {}", name,
                          failures.size(), failures.front().id,
                          rc::to_string(failures.front().kind), failures.front().message());
      }
    }
    if (code == RTC_OK && c.refusals.count > 0) {
      code = c.refusals.first_code;
      why = fmt::format("{} mnp_move() call(s) were refused; the first: {}", c.refusals.count,
                        c.refusals.first);
    }
    (void)power_off;  // the cell's robots hold; simulated arms have no power to cut
    return code == RTC_OK ? RTC_OK : fail(code, "rcclRelease: " + why, Say::quiet);
  });
}

int mnp_setvel(MANIP* m, double mm_per_s, double deg_per_s) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_setvel");
  State& s = state();
  const rc::MotionSettings saved = s.settings;
  const int code = setvel(mm_per_s, deg_per_s);  // the same checks and words
  if (code == RTC_OK) {
    r->settings.translation_m_per_s = s.settings.translation_m_per_s;
    r->settings.rotation_rad_per_s = s.settings.rotation_rad_per_s;
  }
  s.settings = saved;
  return code;
}

int mnp_setmod(MANIP* m, int mode) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_setmod");
  State& s = state();
  const rc::MotionSettings saved = s.settings;
  const int code = setmod(mode);
  if (code == RTC_OK) r->settings.mode = s.settings.mode;
  s.settings = saved;
  return code;
}

int mnp_settime(MANIP* m, double transition_ms, double segment_ms) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_settime");
  State& s = state();
  const rc::MotionSettings saved = s.settings;
  const int code = settime(transition_ms, segment_ms);
  if (code == RTC_OK) {
    r->settings.transition_time_s = s.settings.transition_time_s;
    r->settings.segment_time_s = s.settings.segment_time_s;
  }
  s.settings = saved;
  return code;
}

int mnp_move(MANIP* m, POS_PTR p) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_move");
  const int code = guarded("mnp_move", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    const auto it = p != nullptr ? s.positions.find(p) : s.positions.end();
    if (it == s.positions.end()) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_move({}, {}): not a position made by makeposition() (or "
                              "mnp_park)",
                              r->name, static_cast<const void*>(p)),
                  Say::print);
    }
    if (!s.cell_session->started) {
      return fail(
          RTC_E_SEQUENCE,
          fmt::format("mnp_move({}, {}): call rcclStart() first", r->name, it->second->name),
          Say::print);
    }
    if (!r->arm->session().controlling()) {
      return fail(
          RTC_E_TERMINATED,
          fmt::format("mnp_move({}, {}): {}'s control has ended: {}", r->name, it->second->name,
                      r->name, describe_end(r->arm->session().termination())),
          Say::print);
    }
    r->arm->set_mode(r->settings.mode);
    r->arm->set_velocity(r->settings.translation_m_per_s, r->settings.rotation_rad_per_s);
    r->arm->set_segment_time(r->settings.segment_time_s);
    r->arm->set_transition_time(r->settings.transition_time_s);
    const rc::PositionPtr target = build_position(*it->second, math::Transform::identity());
    const rc::Motion mo = r->arm->move(target, r->next);
    it->second->queued.push_back(target);
    r->next = rc::StartWhen{};
    r->motion_names[mo.id] = it->second->name;
    r->motion_boxes[mo.id] = it->second.get();
    refresh();
    return RTC_OK;
  });
  if (State& s = state(); s.cell_session) s.cell_session->refusals.note(code);
  return code;
}

int mnp_last_motion(const MANIP* m) {
  const rccl_manip* r = known(m);
  return r == nullptr ? 0 : static_cast<int>(r->arm->last_queued());
}

int mnp_touch(MANIP* m, const char* objects) {
  rccl_manip* r = known(m);
  if (r == nullptr) return bad_handle("mnp_touch");
  return guarded("mnp_touch", Say::print, RTC_E_ARGUMENT, [&] {
    std::vector<std::string> names;
    std::string word;
    for (const char* c = objects != nullptr ? objects : "";; ++c) {
      if (*c == '\0' || *c == ',' || *c == ' ') {
        if (!word.empty()) names.push_back(word);
        word.clear();
        if (*c == '\0') break;
      } else {
        word += *c;
      }
    }
    try {
      r->next.touch = state().cell_session->cell->objects(names);
    } catch (const std::invalid_argument& e) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_touch({}, \"{}\"): {}", r->name,
                              objects != nullptr ? objects : "", e.what()),
                  Say::print);
    }
    return RTC_OK;
  });
}

int mnp_after(MANIP* m, MANIP* other, int motion, int event) {
  rccl_manip* r = known(m);
  rccl_manip* o = known(other);
  if (r == nullptr || o == nullptr) return bad_handle("mnp_after");
  return guarded("mnp_after", Say::print, RTC_E_ARGUMENT, [&] {
    if (event != RCCL_START && event != RCCL_END) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_after({}, {}, {}, {}): the event is RCCL_START or RCCL_END",
                              r->name, o->name, motion, event),
                  Say::print);
    }
    if (motion < 1 || static_cast<std::uint64_t>(motion) > o->arm->last_queued()) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_after({}, {}, {}): {} has queued {}; take the number "
                              "from mnp_last_motion() after its mnp_move",
                              r->name, o->name, motion, o->name,
                              o->arm->last_queued() == 0
                                  ? std::string("no motion yet")
                                  : fmt::format("motions 1 .. {}", o->arm->last_queued())),
                  Say::print);
    }
    if (r->next.after.size() >= rc::StartWhen::kMaxGates) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("mnp_after({}): a motion waits for at most {} events", r->name,
                              rc::StartWhen::kMaxGates),
                  Say::print);
    }
    const rc::Motion mo{static_cast<std::uint64_t>(motion)};
    r->next.after.push_back(
        state().cell_session->cell->event(o->name, event == RCCL_START ? mo.start() : mo.end()));
    return RTC_OK;
  });
}

int rccl_together(int end_together, ...) {
  std::array<MANIP*, rc::Rendezvous::kMaxParticipants + 1> list{};
  std::size_t n = 0;
  std::va_list ap;
  va_start(ap, end_together);
  for (; n < list.size(); ++n) {
    list[n] = va_arg(ap, MANIP*);
    if (list[n] == nullptr) break;
  }
  va_end(ap);
  return guarded("rccl_together", Say::print, RTC_E_ARGUMENT, [&] {
    State& s = state();
    if (n == list.size()) {
      return fail(RTC_E_ARGUMENT,
                  "rccl_together: more than 64 robots: is the NULL that ends the list missing?",
                  Say::print);
    }
    std::vector<std::string> names;
    for (std::size_t i = 0; i < n; ++i) {
      const rccl_manip* r = known(list[i]);
      if (r == nullptr) return bad_handle("rccl_together");
      names.push_back(r->name);
    }
    if (!s.cell_session) return fail(RTC_E_SEQUENCE, "rccl_together: no cell is open", Say::print);
    const rccx::cell::Together t = s.cell_session->cell->together(names, end_together != 0);
    for (std::size_t i = 0; i < n; ++i) {
      rccl_manip* r = known(list[i]);
      r->next.together = t.rendezvous;
      r->next.slot = i;
    }
    return RTC_OK;
  });
}

int mnp_started(const MANIP* m, int motion) {
  const rccl_manip* r = known(m);
  if (r == nullptr || motion < 0) return 0;
  return r->arm->happened(rc::Motion{static_cast<std::uint64_t>(motion)}.start()) ? 1 : 0;
}

int mnp_ended(const MANIP* m, int motion) {
  const rccl_manip* r = known(m);
  if (r == nullptr || motion < 0) return 0;
  return r->arm->happened(rc::Motion{static_cast<std::uint64_t>(motion)}.end()) ? 1 : 0;
}

int mnp_completed(const MANIP* m) {
  const rccl_manip* r = known(m);
  return r != nullptr && r->arm->happened(rc::Manipulator::completed()) ? 1 : 0;
}

POS_PTR mnp_park(MANIP* m) {
  return member_of(m, "mnp_park", &rccl_manip::park);
}

TRSF_PTR mnp_tool(MANIP* m) {
  return member_of(m, "mnp_tool", &rccl_manip::tool);
}

TRSF_PTR mnp_base_inv(MANIP* m) {
  return member_of(m, "mnp_base_inv", &rccl_manip::base_inv);
}

TRSF_PTR mnp_tool_frame(MANIP* leader) {
  return member_of(leader, "mnp_tool_frame", &rccl_manip::tool_frame);
}

}  // extern "C"
