// The transform and vector algebra of rccl.h (the manual's "basic components"): plain values in
// the program's units (mm, deg), on any TRSF or VECT. Each computes in rccx::math and writes
// the result last, so results may alias arguments. No state, no errors.
#include <array>
#include <cstdio>
#include <numbers>

#include "compat_internal.hpp"

namespace {

namespace math = rccx::math;
using rccx::compat::to_c;
using rccx::compat::to_math;

constexpr double kRad = std::numbers::pi / 180.0;

/// The rotation and position of t, p in mm (algebra keeps the program's units).
math::Transform value_mm(const TRSF* t) noexcept {
  math::Transform out;
  out.R.n = to_math(t->n);
  out.R.o = to_math(t->o);
  out.R.a = to_math(t->a);
  out.p = to_math(t->p);
  return out;
}

TRSF_PTR put(TRSF_PTR r, const math::Transform& v) noexcept {
  r->n = to_c(v.R.n);
  r->o = to_c(v.R.o);
  r->a = to_c(v.R.a);
  r->p = to_c(v.p);
  return r;
}

TRSF_PTR put_rotation(TRSF_PTR r, const math::Rot3& R) noexcept {
  return put(r, math::Transform{R, {}});
}

}  // namespace

extern "C" {

TRSF_PTR trmult(TRSF_PTR r, const TRSF* t1, const TRSF* t2) {
  return put(r, value_mm(t1) * value_mm(t2));
}

TRSF_PTR trmultinv(TRSF_PTR r, const TRSF* t1, const TRSF* t2) {
  return put(r, value_mm(t1) * value_mm(t2).inverse());
}

TRSF_PTR invtrmult(TRSF_PTR r, const TRSF* t1, const TRSF* t2) {
  return put(r, value_mm(t1).inverse_times(value_mm(t2)));
}

TRSF_PTR invert(TRSF_PTR r, const TRSF* t) {
  return put(r, value_mm(t).inverse());
}

TRSF_PTR assigntr(TRSF_PTR r, const TRSF* t) {
  return put(r, value_mm(t));
}

TRSF_PTR ident(TRSF_PTR r) {
  return put(r, math::Transform::identity());
}

TRSF_PTR rot(TRSF_PTR r, VECT axis, double angle_deg) {
  return put_rotation(r, math::Rot3::about(to_math(axis), angle_deg * kRad));
}

TRSF_PTR trsl(TRSF_PTR r, double x_mm, double y_mm, double z_mm) {
  return put(r, math::Transform::translation(x_mm, y_mm, z_mm));
}

TRSF_PTR eul(TRSF_PTR r, double phi_deg, double theta_deg, double psi_deg) {
  return put_rotation(r, math::Rot3::from_zyz(phi_deg * kRad, theta_deg * kRad, psi_deg * kRad));
}

TRSF_PTR rpy(TRSF_PTR r, double roll_deg, double pitch_deg, double yaw_deg) {
  return put_rotation(r, math::Rot3::from_rpy(roll_deg * kRad, pitch_deg * kRad, yaw_deg * kRad));
}

TRSF_PTR rotr(TRSF_PTR r, VECT axis, double angle_deg) {
  return put(r,
             value_mm(r) * math::Transform{math::Rot3::about(to_math(axis), angle_deg * kRad), {}});
}

TRSF_PTR trslr(TRSF_PTR r, double x_mm, double y_mm, double z_mm) {
  return put(r, value_mm(r) * math::Transform::translation(x_mm, y_mm, z_mm));
}

TRSF_PTR takerot(TRSF_PTR r, const TRSF* t) {
  const VECT n = t->n, o = t->o, a = t->a;
  r->n = n;
  r->o = o;
  r->a = a;
  return r;
}

TRSF_PTR taketrsl(TRSF_PTR r, const TRSF* t) {
  r->p = t->p;
  return r;
}

const TRSF* trtoeul(const TRSF* t, double* phi_deg, double* theta_deg, double* psi_deg) {
  const std::array<double, 3> a = value_mm(t).R.to_zyz();
  if (phi_deg != nullptr) *phi_deg = a[0] / kRad;
  if (theta_deg != nullptr) *theta_deg = a[1] / kRad;
  if (psi_deg != nullptr) *psi_deg = a[2] / kRad;
  return t;
}

const TRSF* trtorpy(const TRSF* t, double* roll_deg, double* pitch_deg, double* yaw_deg) {
  const std::array<double, 3> a = value_mm(t).R.to_rpy();
  if (roll_deg != nullptr) *roll_deg = a[0] / kRad;
  if (pitch_deg != nullptr) *pitch_deg = a[1] / kRad;
  if (yaw_deg != nullptr) *yaw_deg = a[2] / kRad;
  return t;
}

VECT_PTR vecmult(VECT_PTR r, const TRSF* t, const VECT* v) {
  *r = to_c(value_mm(t) * to_math(*v));
  return r;
}

VECT_PTR rotvec(VECT_PTR r, const TRSF* t, const VECT* v) {
  *r = to_c(value_mm(t).R * to_math(*v));
  return r;
}

VECT_PTR vecadd(VECT_PTR r, const VECT* u, const VECT* v) {
  *r = to_c(to_math(*u) + to_math(*v));
  return r;
}

VECT_PTR vecsub(VECT_PTR r, const VECT* u, const VECT* v) {
  *r = to_c(to_math(*u) - to_math(*v));
  return r;
}

VECT_PTR vecscale(VECT_PTR r, const VECT* v, double s) {
  *r = to_c(to_math(*v) * s);
  return r;
}

VECT_PTR cross(VECT_PTR r, const VECT* u, const VECT* v) {
  *r = to_c(math::cross(to_math(*u), to_math(*v)));
  return r;
}

VECT_PTR unit(VECT_PTR r, const VECT* v) {
  *r = to_c(to_math(*v).normalized());
  return r;
}

double dot(const VECT* u, const VECT* v) {
  return math::dot(to_math(*u), to_math(*v));
}

double norm(const VECT* v) {
  return to_math(*v).norm();
}

const TRSF* printr(const TRSF* t, FILE* fp) {
  if (fp == nullptr) fp = stdout;
  const char* name = t->name != nullptr && t->name[0] != '\0' ? t->name : "(transform)";
  std::fprintf(fp, "%s:\n", name);
  std::fprintf(fp, "  %10.6f %10.6f %10.6f %12.4f\n", t->n.x, t->o.x, t->a.x, t->p.x);
  std::fprintf(fp, "  %10.6f %10.6f %10.6f %12.4f\n", t->n.y, t->o.y, t->a.y, t->p.y);
  std::fprintf(fp, "  %10.6f %10.6f %10.6f %12.4f\n", t->n.z, t->o.z, t->a.z, t->p.z);
  return t;
}

const VECT* printv(const VECT* v, FILE* fp) {
  if (fp == nullptr) fp = stdout;
  std::fprintf(fp, "(%.6g, %.6g, %.6g)\n", v->x, v->y, v->z);
  return v;
}

}  // extern "C"
