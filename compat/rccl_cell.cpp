// The workcell part of rccl.h (Multi-RCCL style): rccl_cell_open, a MANIP handle per robot,
// the mnp_ calls, rccl_together. Positions and transforms are shared with the one-robot calls
// (compat_internal.hpp); waitfor() lets one tick of the cell's clock run.
//
// The cell is a cell::Workcell: cell::Cell (every robot in this process, simulated time), or
// net::RemoteCell (robots of `rccx serve` processes, real time) when RCCX_CELL_REMOTE=1 or
// rccl_cell_open_remote() asks for it (docs/NETWORK.md, "The C interface across processes").
#include <array>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "rccx/io/data_files.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/net/remote_cell.hpp"
// rccx's headers before the C ones (compat_internal.hpp)
#include "compat_internal.hpp"
#include "compat_shared.hpp"

namespace rccx::compat {

namespace {

using namespace std::chrono_literals;

/// Why robot m does not run ("" while it does): its control ended, or (across processes) its
/// serve process is lost, which waiting cannot mend within the program's wait.
std::string not_running(rccl_manip& m) {
  if (m.local != nullptr) {
    return m.local->session().controlling() ? std::string()
                                            : describe_end(m.local->session().termination());
  }
  if (m.remote->mirror().lost()) {
    const std::vector<rc::MotionEvent>& f = m.arm->failures();
    return f.empty() ? fmt::format("robot {} lost: its serve process is silent", m.name)
                     : std::string(f.back().message());
  }
  const rtc::Termination t = m.arm->wait_for(0ns);  // the state's terminate code, at once
  return t.ended() ? describe_end(t) : std::string();
}

/// A remote arm's motions that ended, failed or were cancelled no longer hold their position's
/// POS.end at 0 (as a local generator's end of segment does); all of them once it is lost.
void retire_in_flight(rccl_manip& m, const std::vector<rc::MotionEvent>& events) {
  const auto retire = [](const rc::PositionPtr& p) {
    p->pending_ends.fetch_sub(1, std::memory_order_acq_rel);
  };
  for (const rc::MotionEvent& e : events) {
    if (e.kind == rc::EventKind::started) continue;
    if (const auto it = m.in_flight.find(e.id); it != m.in_flight.end()) {
      retire(it->second);
      m.in_flight.erase(it);
    }
  }
  if (m.remote->mirror().lost() || m.arm->wait_for(0ns).ended()) {
    for (const auto& [id, p] : m.in_flight) retire(p);
    m.in_flight.clear();
  }
}

/// Prints the motions of robot m that failed since the last call; true when its control has
/// ended (printed once).
bool cell_report(rccl_manip& m) {
  // POS.code of each motion's position, as move() sets it for one robot: 0 when it ended,
  // RCCL_NEXTMOVE / RCCL_ONF ended early, RTC_E_MOTION failed or cancelled (a collision stop).
  const std::vector<rc::MotionEvent> events = show_motion_codes(*m.arm, m.motion_boxes);
  if (m.remote != nullptr) retire_in_flight(m, events);
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
  const std::string why = not_running(m);
  if (why.empty()) return false;
  if (!m.told_ended) {
    m.told_ended = true;
    fail(RTC_E_TERMINATED, fmt::format("{}: {}", m.name, why), Say::print);
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

/// The network options of a remote cell: the domain given (< 0: $RCCX_DOMAIN, else 0), the
/// interface from $RCCX_DDS_INTERFACE, the detection time from $RCCX_DETECTION_MS, DDS Security
/// from $RCCX_SECURE_DIR (`rccx certs init`'s directory) as $RCCX_SECURE_IDENTITY ("program").
rccx::net::NetOptions remote_options(int domain) {
  rccx::net::NetOptions o;
  if (domain >= 0) o.domain = static_cast<std::uint32_t>(domain);
  if (const char* env = std::getenv("RCCX_SECURE_DIR"); env != nullptr && *env != '\0') {
    o.secure_dir = env;
    const char* id = std::getenv("RCCX_SECURE_IDENTITY");
    o.secure_identity = id != nullptr && *id != '\0' ? id : "program";
  }
  if (const char* env = std::getenv("RCCX_DETECTION_MS"); env != nullptr && *env != '\0') {
    o.detection = std::chrono::milliseconds(
        rccx::io::parse_integer(env, "RCCX_DETECTION_MS (ms, 1 .. 10000)", 1, 10000));
    o.heartbeat = o.detection / 4;
  }
  return o;
}

/// rccl_cell_open's checks and the cell file's path (RCCX_CELL, the shipped cvarl.json).
int open_checks(const char* call, const char* cell_file, std::string& path) {
  const State& s = state();
  if (s.arm_session || s.cell_session) {
    return fail(
        RTC_E_SEQUENCE,
        fmt::format("{}: a session or cell is open; rccl_close() or rcclRelease() it first", call),
        Say::quiet);
  }
  if (rtc_session_open()) {
    return fail(RTC_E_SEQUENCE,
                fmt::format("{}: an RTC session (control, rtc_open) is open; release() or "
                            "rtc_close() it first",
                            call),
                Say::quiet);
  }
  path = cell_file != nullptr ? cell_file : "";
  if (path.empty()) {
    if (const char* env = std::getenv("RCCX_CELL"); env != nullptr) path = env;
  }
  try {
    // $RCCX_DATA_DIR, the source tree, the installed copy (rccx/io/data_files.hpp).
    if (path.empty()) path = rccx::io::find_data_file("cells/cvarl.json").string();
  } catch (const rccx::io::DataFileError& e) {
    return fail(RTC_E_ROBOT, fmt::format("{}: {}; or set RCCX_CELL", call, e.what()), Say::quiet);
  }
  return RTC_OK;
}

/// Joins the robots of the cell file `path` that serve processes run on `domain`.
int open_remote(const std::string& path, int domain) {
  const char* call = "rccl_cell_open_remote";
  if (domain < -1 || domain > 232) {
    return fail(
        RTC_E_ARGUMENT,
        fmt::format("{}: DDS domain {}: give 0 .. 232, or -1 for $RCCX_DOMAIN", call, domain),
        Say::quiet);
  }
  std::unique_ptr<rccx::net::RemoteCell> joined;
  try {
    joined = std::make_unique<rccx::net::RemoteCell>(rccx::cell::load_cell_file(path),
                                                     remote_options(domain));
  } catch (const rccx::cell::CellFileError& e) {
    return fail(RTC_E_ROBOT, fmt::format("{}: {}", call, e.what()), Say::quiet);
  } catch (const rccx::net::NetError& e) {
    return fail(RTC_E_OPEN, fmt::format("{}: {}", call, e.what()), Say::quiet);
  }
  state().cell_session.emplace(std::move(joined));
  refresh();
  return RTC_OK;
}

}  // namespace

CellSession::CellSession(std::unique_ptr<rccx::cell::Cell> loaded) : local(loaded.get()) {
  cell = std::move(loaded);
}

CellSession::CellSession(std::unique_ptr<rccx::net::RemoteCell> joined) : remote(joined.get()) {
  cell = std::move(joined);
}

bool cell_event_done(rccl_manip& m, const rc::Event& e) {
  if (m.remote == nullptr) return m.arm->happened(e);
  // The remote ledger answers "never" for a motion that failed: done, as in one process.
  return (m.arm->waitfor)(e, 0ns) != rc::WaitResult::timeout;  // not rccl.h's macro
}

/// waitfor() with a cell: one tick of the cell's clock.
int cell_wait_tick() {
  CellSession& c = *state().cell_session;
  if (!c.started) {
    return fail(RTC_E_SEQUENCE, "waitfor: call rcclStart() before waiting on the cell", Say::print);
  }
  if (c.local != nullptr) {
    bool any = false;
    for (auto& [name, m] : c.manips) any = any || m->local->session().controlling();
    if (any) c.cell->wait_for(c.local->group().period());
  } else {
    // Real time: the serve processes' states come about every period; 1 ms keeps up with them.
    c.cell->wait_for(1ms);
  }
  bool all_ended = true;
  for (auto& [name, m] : c.manips) all_ended = cell_report(*m) && all_ended;
  if (!c.manips.empty()) {
    const rccl_manip& first = *c.manips.begin()->second;
    if (first.local != nullptr) {
      const rtc::How how = first.local->session().how();
      rtime = std::lround(how.time_s * 1e3);
      rccl_sample = static_cast<long>(how.sample);
    } else {
      const rccx::net::RemoteState st = first.remote->state();  // its serve process's clock
      rtime = std::lround(st.t_s * 1e3);
      rccl_sample = static_cast<long>(st.sample);
    }
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
    std::string path;
    if (const int code = open_checks("rccl_cell_open", cell_file, path); code != RTC_OK) {
      return code;
    }
    // The switch of a program that does not change: RCCX_CELL_REMOTE=1 (docs/NETWORK.md).
    if (const char* env = std::getenv("RCCX_CELL_REMOTE"); env != nullptr && *env != '\0') {
      const std::string_view v(env);
      if (v == "1") return open_remote(path, -1);
      if (v != "0") {
        return fail(RTC_E_ARGUMENT,
                    fmt::format("rccl_cell_open: RCCX_CELL_REMOTE is \"{}\": 1 joins the robots "
                                "served by `rccx serve` processes, 0 or unset runs them here",
                                v),
                    Say::quiet);
      }
    }
    std::unique_ptr<rccx::cell::Cell> loaded;
    try {
      loaded = rccx::cell::Cell::load(path);
    } catch (const rccx::cell::CellFileError& e) {
      return fail(RTC_E_ROBOT, fmt::format("rccl_cell_open: {}", e.what()), Say::quiet);
    }
    state().cell_session.emplace(std::move(loaded));
    refresh();
    return RTC_OK;
  });
}

int rccl_cell_open_remote(const char* cell_file, int domain) {
  return guarded("rccl_cell_open_remote", Say::quiet, RTC_E_ROBOT, [&] {
    std::string path;
    if (const int code = open_checks("rccl_cell_open_remote", cell_file, path); code != RTC_OK) {
      return code;
    }
    return open_remote(path, domain);
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
    // std::invalid_argument names the cell's robots
    if (c.local != nullptr) {
      m->local = &c.local->robot(n);
      m->arm = m->local;
    } else {
      m->remote = &c.remote->robot(n);
      m->arm = m->remote;
    }
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
      // A remote robot goes on with its serve process: the program leaving (the cell's
      // destructor) is what that process acts on; here, how its control ended, if it did.
      const rtc::Termination t = m->local == nullptr ? m->arm->wait_for(0ns)
                                 : c.started         ? m->local->stop_control()
                                                     : m->local->session().termination();
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
    if (const std::string why = not_running(*r); !why.empty()) {
      return fail(RTC_E_TERMINATED,
                  fmt::format("mnp_move({}, {}): {} does not run: {}", r->name, it->second->name,
                              r->name, why),
                  Say::print);
    }
    r->arm->set_mode(r->settings.mode);
    r->arm->set_velocity(r->settings.translation_m_per_s, r->settings.rotation_rad_per_s);
    r->arm->set_segment_time(r->settings.segment_time_s);
    r->arm->set_transition_time(r->settings.transition_time_s);
    const rc::PositionPtr target = build_position(*it->second, math::Transform::identity());
    const rc::Motion mo = r->arm->move(target, r->next);
    if (r->remote != nullptr) {  // POS.end: counted here as a local generator counts it
      target->pending_ends.fetch_add(1, std::memory_order_acq_rel);
      r->in_flight[mo.id] = target;
    }
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
    if (s.cell_session->local == nullptr) {
      return fail(RTC_E_NOT_YET,
                  "rccl_together: a joint start across processes (a remote cell) is not "
                  "supported yet; chain the motions with mnp_after(m, other, motion, RCCL_START)",
                  Say::print);
    }
    const rccx::cell::Together t = s.cell_session->local->together(names, end_together != 0);
    for (std::size_t i = 0; i < n; ++i) {
      rccl_manip* r = known(list[i]);
      r->next.together = t.rendezvous;
      r->next.slot = i;
    }
    return RTC_OK;
  });
}

int mnp_started(const MANIP* m, int motion) {
  rccl_manip* r = known(m);
  if (r == nullptr || motion < 0) return 0;
  return r->arm->happened(rc::Motion{static_cast<std::uint64_t>(motion)}.start()) ? 1 : 0;
}

int mnp_ended(const MANIP* m, int motion) {
  rccl_manip* r = known(m);
  if (r == nullptr || motion < 0) return 0;
  return cell_event_done(*r, rc::Motion{static_cast<std::uint64_t>(motion)}.end()) ? 1 : 0;
}

int mnp_completed(const MANIP* m) {
  rccl_manip* r = known(m);
  return r != nullptr && cell_event_done(*r, rc::Arm::completed()) ? 1 : 0;
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
