// The C side of BM_SetpointCartesian2CFunctional (rccl_bench.cpp): the same two moving
// transforms as the C++ case, CONV and OBJ, written as an RCCL program writes them - C
// functions that set a TRSF (mm) from rtime - and made with newtrans. Apart from rccl_bench.cpp
// because rccl.h's macros (Rot, Trsl, EQ, ...) must not meet the rest of the benchmarks.
#include <cmath>
#include <utility>

#include "compat_internal.hpp"

namespace {

constexpr double kConveyorSpeedMmPerMs = 0.002;  // 2 mm/s, as kConveyorSpeed
constexpr double kObjectSpeedMmPerMs = 0.001;    // 1 mm/s, as kObjectSpeed
rccx::math::Vec3 object_mm;

int conv_fn(TRSF_PTR t) {
  Trsl(t, 0.0, kConveyorSpeedMmPerMs * static_cast<double>(rtime), 0.0);
  return 0;
}

int obj_fn(TRSF_PTR t) {
  Trsl(t, object_mm.x, object_mm.y, object_mm.z + kObjectSpeedMmPerMs * static_cast<double>(rtime));
  return 0;
}

}  // namespace

namespace rccx::bench {

/// CONV and OBJ (object at `obj`, m) as the sample loop sees C functional transforms.
std::pair<rccl::TransformPtr, rccl::TransformPtr> c_moving_transforms(const math::Vec3& obj) {
  object_mm = obj * 1e3;
  TRSF_PTR conv = newtrans("CONV", conv_fn);
  TRSF_PTR o = newtrans("OBJ", obj_fn);
  return {compat::box_of(conv)->live, compat::box_of(o)->live};
}

}  // namespace rccx::bench
