// The transforms of rccl.h: newtrans, the gentr_ family, and what stands behind a TRSF in the
// position equations rccx builds (compat_internal.hpp). The algebra on TRSF values is in
// rccl_algebra.cpp.
//
// A TRSF's n, o, a, p are the program's: it may write them at any time between waits. So const
// and hold transforms are read at each move() (build_position), and varb and functional ones
// are rccx functional transforms that read the struct (a functional one after calling the
// program's function) once per sample.
#include <fmt/ranges.h>

#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "compat_internal.hpp"

namespace rccx::compat {

namespace {

/// The C function of a functionally defined transform, as it is called: fn(t).
using TransformFn = int (*)(TRSF*);

void note_sample(const rc::SampleContext& ctx) noexcept {
  rtime = std::lround(ctx.t_s * 1e3);
  rccl_sample = static_cast<long>(ctx.sample);
}

/// t6's value for the functions of this sample: the arm's measured T6 (a monitor's sensor),
/// computed once a sample.
void measured_t6_in_loop(const rc::SampleContext& ctx) noexcept {
  TrsfBox& t6b = t6_box();
  const long sample = static_cast<long>(ctx.sample);
  if (t6b.c.age == sample) return;
  const State& s = state();
  const kin::Kinematics* k = s.arm_session ? &s.arm_session->arm.kinematics() : nullptr;
  if (k == nullptr || ctx.how->dof != k->dof()) return;  // a cell: several arms, no one T6
  to_c(k->forward(ctx.how->q()), t6b.c);
  t6b.c.age = sample;
}

/// A functional's value: the struct after its function ran this sample; the last finite value
/// when the function left something that is not a number (what the arm should not follow).
/// Asked for another time than the sample's (the generator planning a transition onto a moving
/// goal): the function is not called - it may count samples, not time - and the position is
/// extrapolated from the last two samples' values (the goal's velocity, estimated).
math::Transform functional_value(TrsfBox& b, const rc::SampleContext& ctx) {
  if (ctx.predicted) {
    math::Transform v = b.last_good;
    const double dt = b.last_t_s - b.previous_t_s;
    if (b.previous_t_s >= 0.0 && b.previous_t_s < b.last_t_s && dt < 1.0) {
      v.p += (b.last_good.p - b.previous_p) * ((ctx.t_s - b.last_t_s) / dt);
    }
    return v;
  }
  if (ctx.how != nullptr) {  // in the sample loop (the planning level reads the value as it is)
    note_sample(ctx);
    measured_t6_in_loop(ctx);
    reinterpret_cast<TransformFn>(b.c.fn)(&b.c);
    b.c.age = static_cast<long>(ctx.sample);
    loop_nextmove();
  }
  const math::Transform v = to_math(b.c);
  const auto& R = v.R;
  if (finite(
          {R.n.x, R.n.y, R.n.z, R.o.x, R.o.y, R.o.z, R.a.x, R.a.y, R.a.z, v.p.x, v.p.y, v.p.z})) {
    if (ctx.how != nullptr) {
      if (ctx.t_s > b.last_t_s) {
        b.previous_p = b.last_good.p;
        b.previous_t_s = b.last_t_s;
      } else {
        b.previous_t_s = -1.0;  // time began again (a new session): no velocity known yet
      }
      b.last_t_s = ctx.t_s;
    }
    b.last_good = v;
  }
  return b.last_good;
}

TRSF_PTR register_box(std::unique_ptr<TrsfBox> box) {
  TRSF_PTR t = &box->c;
  box->c.name = box->name.c_str();
  box->c.rccx = box.get();
  box->c.age = -1;
  state().transforms.emplace(t, std::move(box));
  return t;
}

/// A new named transform of `type` with value `value` (not yet checked).
TRSF_PTR make_trsf(std::string name, int type, RCCL_FN fn, const math::Transform& value) {
  auto box = std::make_unique<TrsfBox>();
  box->name = std::move(name);
  to_c(value, box->c);
  box->c.type = type;
  box->c.fn = fn;
  box->last_good = value;
  TrsfBox* b = box.get();
  if (type == RCCL_VARB) {
    box->live = rc::functional(box->name, [b](const rc::SampleContext& ctx) {
      if (ctx.how != nullptr && !ctx.predicted) note_sample(ctx);
      return to_math(b->c);
    });
  } else if (type == RCCL_FUNCT) {
    box->live = rc::functional(
        box->name, [b](const rc::SampleContext& ctx) { return functional_value(*b, ctx); });
  }
  return register_box(std::move(box));
}

const char* type_name(int type) {
  switch (type) {
    case RCCL_CONST:
      return "const";
    case RCCL_VARB:
      return "varb";
    case RCCL_HOLD:
      return "hold";
    case RCCL_FUNCT:
      return "functional";
    default:
      return "?";
  }
}

/// gentr_*: a constant transform from a value computed by `make`, checked.
template <class F>
TRSF_PTR gentr(const char* call, const char* name, std::initializer_list<double> numbers,
               F&& make) {
  TRSF_PTR out = nullptr;
  guarded(call, Say::print, RTC_E_ARGUMENT, [&] {
    const std::string n = name != nullptr ? name : "?";
    if (!finite(numbers)) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("{}({}): every number must be finite (got {})", call, n,
                              fmt::join(numbers, ", ")),
                  Say::print);
    }
    std::string problem;
    const math::Transform value = make(problem);
    if (!problem.empty()) {
      return fail(RTC_E_ARGUMENT, fmt::format("{}({}): {}", call, n, problem), Say::print);
    }
    out = make_trsf(n, RCCL_CONST, nullptr, value);
    return RTC_OK;
  });
  return out;
}

math::Vec3 mm(double x, double y, double z) noexcept {
  return {x * 1e-3, y * 1e-3, z * 1e-3};
}

double rad(double deg) noexcept {
  return deg * (std::numbers::pi / 180.0);
}

}  // namespace

bool finite(std::initializer_list<double> values) noexcept {
  for (const double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

math::Vec3 to_math(const VECT& v) noexcept {
  return {v.x, v.y, v.z};
}

VECT to_c(const math::Vec3& v) noexcept {
  return {v.x, v.y, v.z};
}

math::Transform to_math(const TRSF& t) noexcept {
  math::Transform out;
  out.R.n = to_math(t.n);
  out.R.o = to_math(t.o);
  out.R.a = to_math(t.a);
  out.p = to_math(t.p) * 1e-3;
  return out;
}

void to_c(const math::Transform& value, TRSF& t) noexcept {
  t.n = to_c(value.R.n);
  t.o = to_c(value.R.o);
  t.a = to_c(value.R.a);
  t.p = to_c(value.p * 1e3);
}

TrsfBox* box_of(const TRSF* t) noexcept {
  if (t == nullptr) return nullptr;
  if (t == &t6_box().c) return &t6_box();
  const State& s = state();
  const auto it = s.transforms.find(t);
  return it == s.transforms.end() ? nullptr : it->second.get();
}

TRSF_PTR keep_transform(const rc::TransformPtr& source) {
  if (source->kind() == rc::TransformKind::constant) {
    return make_trsf(source->name(), RCCL_CONST, nullptr, source->value());
  }
  auto box = std::make_unique<TrsfBox>();
  box->name = source->name();
  box->c.type = RCCL_SYSTEM;
  box->source = source;
  TrsfBox* b = box.get();
  box->live = rc::functional(box->name, [b](const rc::SampleContext& ctx) {
    const bool in_loop = ctx.how != nullptr && !ctx.predicted;  // predictions are not cached
    const math::Transform v = in_loop ? b->source->evaluate(ctx) : b->source->value_now(ctx);
    if (in_loop) to_c(v, b->c);
    return v;
  });
  // A robot's tool frame ("frame:puma") stays one a serve process can resolve (net::codec).
  box->live->set_reference(source->reference());
  to_c(math::Transform::identity(), box->c);
  return register_box(std::move(box));
}

rc::TransformPtr transform_now(TrsfBox& b, bool as_hold) {
  if (&b == &t6_box()) return b.live;
  if (b.c.type == RCCL_CONST || b.c.type == RCCL_HOLD || as_hold) {
    const math::Transform value = to_math(b.c);
    if (!rc::is_rigid(value)) {
      throw rc::EquationError(fmt::format(
          "transform {} ({}) is not a rigid transform: its n, o, a must be orthonormal unit "
          "vectors with n = o x a (n ({}, {}, {}), o ({}, {}, {}), a ({}, {}, {})); set it with "
          "rot, eul, rpy or assigntr",
          b.name, type_name(b.c.type), b.c.n.x, b.c.n.y, b.c.n.z, b.c.o.x, b.c.o.y, b.c.o.z,
          b.c.a.x, b.c.a.y, b.c.a.z));
    }
    if (!std::isfinite(b.c.p.x) || !std::isfinite(b.c.p.y) || !std::isfinite(b.c.p.z)) {
      throw rc::EquationError(fmt::format("transform {}: its position p is not finite", b.name));
    }
    return as_hold ? rc::hold(b.name, value) : rc::constant(b.name, value);
  }
  return b.live;
}

rc::PositionPtr build_position(const PositionBox& p, const math::Transform& extra, const TRSF* x,
                               rc::TransformPtr* x_out) {
  if (p.joints) return p.joints;
  const auto factor = [&](const TRSF* t) {
    TrsfBox* b = box_of(t);
    rc::TransformPtr f = transform_now(*b, t == x);
    if (t == x && x_out != nullptr) *x_out = f;
    return f;
  };
  std::vector<rc::TransformPtr> lhs, rhs;
  rc::TransformPtr tool;
  for (const TRSF* t : p.lhs) {
    lhs.push_back(factor(t));
    if (t == p.tool) tool = lhs.back();
  }
  for (const TRSF* t : p.rhs) rhs.push_back(factor(t));
  const math::Transform I = math::Transform::identity();
  const bool displaced = !(extra.p == I.p && extra.R.n == I.R.n && extra.R.o == I.R.o);
  if (displaced) {
    rhs.push_back(rc::constant(p.name + " distance", extra));
  }
  return rc::Position::make(p.name, lhs, rhs, tool);
}

}  // namespace rccx::compat

using namespace rccx::compat;

extern "C" {

long rtime = 0;
long rccl_sample = 0;
const VECT xunit = {1.0, 0.0, 0.0};
const VECT yunit = {0.0, 1.0, 0.0};
const VECT zunit = {0.0, 0.0, 1.0};

TRSF_PTR rccl_newtrans(const char* name, int type, RCCL_FN fn) {
  TRSF_PTR out = nullptr;
  guarded("newtrans", Say::print, RTC_E_ARGUMENT, [&] {
    const std::string n = name != nullptr ? name : "?";
    if (type != RCCL_CONST && type != RCCL_VARB && type != RCCL_HOLD && type != RCCL_FUNCT) {
      return fail(
          RTC_E_ARGUMENT,
          fmt::format("newtrans({}, {}): the type is const, varb, hold or a function", n, type),
          Say::print);
    }
    if (type == RCCL_FUNCT && fn == nullptr) {
      return fail(RTC_E_ARGUMENT,
                  fmt::format("newtrans({}): a NULL function; give const, varb, hold or the name "
                              "of a function fn(t) that sets t's value",
                              n),
                  Say::print);
    }
    out = make_trsf(n, type, type == RCCL_FUNCT ? fn : nullptr, math::Transform::identity());
    return RTC_OK;
  });
  return out;
}

TRSF_PTR gentr_trsl(const char* name, double x_mm, double y_mm, double z_mm) {
  return gentr("gentr_trsl", name, {x_mm, y_mm, z_mm},
               [&](std::string&) { return math::Transform::translation(mm(x_mm, y_mm, z_mm)); });
}

TRSF_PTR gentr_rot(const char* name, double x_mm, double y_mm, double z_mm, VECT axis,
                   double angle_deg) {
  return gentr("gentr_rot", name, {x_mm, y_mm, z_mm, axis.x, axis.y, axis.z, angle_deg},
               [&](std::string& problem) {
                 const math::Vec3 a = to_math(axis);
                 if (!(a.norm() > 0.0)) {
                   problem =
                       "the rotation axis is zero; use xunit, yunit, zunit or any "
                       "nonzero VECT";
                 }
                 return math::Transform{math::Rot3::about(a, rad(angle_deg)), mm(x_mm, y_mm, z_mm)};
               });
}

TRSF_PTR gentr_eul(const char* name, double x_mm, double y_mm, double z_mm, double phi_deg,
                   double theta_deg, double psi_deg) {
  return gentr(
      "gentr_eul", name, {x_mm, y_mm, z_mm, phi_deg, theta_deg, psi_deg}, [&](std::string&) {
        return math::Transform{math::Rot3::from_zyz(rad(phi_deg), rad(theta_deg), rad(psi_deg)),
                               mm(x_mm, y_mm, z_mm)};
      });
}

TRSF_PTR gentr_rpy(const char* name, double x_mm, double y_mm, double z_mm, double roll_deg,
                   double pitch_deg, double yaw_deg) {
  return gentr(
      "gentr_rpy", name, {x_mm, y_mm, z_mm, roll_deg, pitch_deg, yaw_deg}, [&](std::string&) {
        return math::Transform{math::Rot3::from_rpy(rad(roll_deg), rad(pitch_deg), rad(yaw_deg)),
                               mm(x_mm, y_mm, z_mm)};
      });
}

TRSF_PTR gentr_pao(const char* name, double px_mm, double py_mm, double pz_mm, double ax, double ay,
                   double az, double ox, double oy, double oz) {
  return gentr("gentr_pao", name, {px_mm, py_mm, pz_mm, ax, ay, az, ox, oy, oz},
               [&](std::string& problem) {
                 const math::Vec3 a = math::Vec3{ax, ay, az}.normalized();
                 const math::Vec3 o0{ox, oy, oz};
                 // o made orthogonal to a (Gram-Schmidt), n = o x a.
                 const math::Vec3 o = (o0 - a * math::dot(o0, a)).normalized();
                 if (!(a.norm() > 0.5) || !(o.norm() > 0.5) ||
                     (o0 - a * math::dot(o0, a)).norm() < 1e-9 * o0.norm()) {
                   problem =
                       "the approach vector a and the orientation vector o must be nonzero "
                       "and not parallel";
                 }
                 math::Transform t;
                 t.R.a = a;
                 t.R.o = o;
                 t.R.n = math::cross(o, a);
                 t.p = mm(px_mm, py_mm, pz_mm);
                 return t;
               });
}

}  // extern "C"
