#include "rccx/net/codec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "rccx/net/dds.hpp"

namespace rccx::net {

namespace {

constexpr std::size_t kName = 32;  // string<32>

void check_name(std::string_view what, std::string_view name) {
  if (name.size() >= kName) {
    throw CodecError(
        fmt::format("{} \"{}\" is {} characters long; a name sent across processes "
                    "has at most {}: give it a shorter name",
                    what, name, name.size(), kName - 1));
  }
}

void encode_term(const rccl::TransformPtr& t, rccx_net_Term& out) {
  out = rccx_net_Term{};
  switch (t->kind()) {
    case rccl::TransformKind::constant:
    case rccl::TransformKind::hold:
      out.kind = static_cast<std::uint8_t>(
          t->kind() == rccl::TransformKind::constant ? TermKind::constant : TermKind::hold);
      check_name("transform", t->name());
      copy_to(out.name, t->name());
      to_pose(t->value(), out.value);
      return;
    case rccl::TransformKind::t6:
      out.kind = static_cast<std::uint8_t>(TermKind::t6);
      copy_to(out.name, "T6");
      return;
    case rccl::TransformKind::functional: {
      const Reference ref = parse_reference(*t);
      check_name(fmt::format("{}'s reference name", t->name()), ref.name);
      out.kind = static_cast<std::uint8_t>(ref.kind);
      copy_to(out.name, ref.name);
      return;
    }
  }
}

}  // namespace

void RequestSample::point() noexcept {
  msg.lhs = {kTermsPerSide, msg.lhs._length, lhs_, false};
  msg.rhs = {kTermsPerSide, msg.rhs._length, rhs_, false};
  msg.after = {kGates, msg.after._length, gates_, false};
}

RequestSample& RequestSample::operator=(const RequestSample& o) noexcept {
  if (this == &o) return *this;
  msg = o.msg;
  std::copy(std::begin(o.lhs_), std::end(o.lhs_), lhs_);
  std::copy(std::begin(o.rhs_), std::end(o.rhs_), rhs_);
  std::copy(std::begin(o.gates_), std::end(o.gates_), gates_);
  point();
  return *this;
}

void to_pose(const math::Transform& t, rccx_net_Pose& out) noexcept {
  // Row-major r: row i is (n_i, o_i, a_i).
  const math::Vec3* cols[3] = {&t.R.n, &t.R.o, &t.R.a};
  for (int c = 0; c < 3; ++c) {
    out.r[0 * 3 + c] = cols[c]->x;
    out.r[1 * 3 + c] = cols[c]->y;
    out.r[2 * 3 + c] = cols[c]->z;
  }
  out.p[0] = t.p.x;
  out.p[1] = t.p.y;
  out.p[2] = t.p.z;
}

math::Transform from_pose(const rccx_net_Pose& p) noexcept {
  math::Transform t;
  math::Vec3* cols[3] = {&t.R.n, &t.R.o, &t.R.a};
  for (int c = 0; c < 3; ++c) {
    cols[c]->x = p.r[0 * 3 + c];
    cols[c]->y = p.r[1 * 3 + c];
    cols[c]->z = p.r[2 * 3 + c];
  }
  t.p = {p.p[0], p.p[1], p.p[2]};
  return t;
}

Reference parse_reference(const rccl::Transform& t) {
  const std::string& ref = t.reference();
  const auto how = [&] {
    return fmt::format(
        "the functional transform {} has {}: a program in another process cannot send its "
        "function. Name it: cell.tool_frame(robot) for another robot's tool (\"frame:<robot>\"), "
        "{}->set_reference(\"function:<name>\") for a function registered in the serve process "
        "(RobotServer::register_function), or a stream the program writes (RemoteCell::stream, "
        "\"stream:<name>\")",
        t.name(), ref.empty() ? "no network name" : fmt::format("the reference \"{}\"", ref),
        t.name());
  };
  const auto colon = ref.find(':');
  if (colon == std::string::npos || colon + 1 >= ref.size()) throw CodecError(how());
  const std::string_view kind = std::string_view(ref).substr(0, colon);
  Reference r;
  r.name = ref.substr(colon + 1);
  if (kind == "frame") {
    r.kind = TermKind::frame;
  } else if (kind == "function") {
    r.kind = TermKind::function;
  } else if (kind == "stream") {
    r.kind = TermKind::stream;
  } else {
    throw CodecError(how());
  }
  return r;
}

void encode_position(const rccl::Position& p, RequestSample& r) {
  check_name("position", p.name());
  RequestSample out = r;  // bad input changes nothing: built aside, then copied
  rccx_net_MotionRequest& m = out.msg;
  copy_to(m.position, p.name());
  m.in_joints = p.in_joints();
  m.dof = 0;
  m.lhs._length = 0;
  m.rhs._length = 0;
  m.tool = 0;
  if (p.in_joints()) {
    const kin::JointVector& q = p.joint_values();
    if (q.size() > 8) throw CodecError(fmt::format("position {}: more than 8 joints", p.name()));
    m.dof = static_cast<std::uint8_t>(q.size());
    for (std::size_t i = 0; i < q.size(); ++i) m.joints[i] = q[i];
    r = out;
    return;
  }
  const auto& lhs = p.lhs();
  const auto& rhs = p.rhs();
  if (lhs.size() > kTermsPerSide || rhs.size() > kTermsPerSide) {
    throw CodecError(
        fmt::format("position {}: {} and {} transforms a side; at most {} a side "
                    "cross processes: multiply constant ones together first",
                    p.name(), lhs.size(), rhs.size(), kTermsPerSide));
  }
  for (std::size_t i = 0; i < lhs.size(); ++i) {
    encode_term(lhs[i], out.add_lhs());
    if (lhs[i] == p.tool_transform()) m.tool = static_cast<std::uint8_t>(i);
  }
  for (const auto& t : rhs) encode_term(t, out.add_rhs());
  r = out;
}

rccl::PositionPtr decode_position(const rccx_net_MotionRequest& r, const Resolver& resolve) {
  const std::string name(text_of(r.position));
  if (r.in_joints) {
    if (r.dof == 0 || r.dof > 8) {
      throw CodecError(fmt::format("position {}: {} joints; 1 .. 8", name, int{r.dof}));
    }
    kin::JointVector q(r.dof);
    for (std::size_t i = 0; i < r.dof; ++i) q[i] = r.joints[i];
    return rccl::Position::joints(name, q);
  }
  // Cyclone checks the bounds when it receives a sample; checked again for a request made here.
  const std::uint32_t n_lhs = r.lhs._length;
  const std::uint32_t n_rhs = r.rhs._length;
  if (n_lhs > kTermsPerSide || n_rhs > kTermsPerSide ||
      r.tool >= std::max<std::uint32_t>(1, n_lhs) || (n_lhs != 0 && r.lhs._buffer == nullptr) ||
      (n_rhs != 0 && r.rhs._buffer == nullptr)) {
    throw CodecError(fmt::format("position {}: malformed ({} and {} terms, tool {})", name, n_lhs,
                                 n_rhs, int{r.tool}));
  }
  const auto term = [&](const rccx_net_Term& t) -> rccl::TransformPtr {
    const std::string tname(text_of(t.name));
    switch (static_cast<TermKind>(t.kind)) {
      case TermKind::constant:
        return rccl::constant(tname, from_pose(t.value));
      case TermKind::hold:
        return rccl::hold(tname, from_pose(t.value));
      case TermKind::t6:
        return rccl::t6();
      case TermKind::frame:
      case TermKind::function:
      case TermKind::stream:
        return resolve(static_cast<TermKind>(t.kind), tname);
    }
    throw CodecError(
        fmt::format("position {}: transform {} of unknown kind {}", name, tname, int{t.kind}));
  };
  std::vector<rccl::TransformPtr> lhs, rhs;
  for (std::uint32_t i = 0; i < n_lhs; ++i) lhs.push_back(term(r.lhs._buffer[i]));
  for (std::uint32_t i = 0; i < n_rhs; ++i) rhs.push_back(term(r.rhs._buffer[i]));
  const rccl::TransformPtr tool = lhs.empty() ? nullptr : lhs[r.tool];
  return rccl::Position::make(name, lhs, rhs, tool);
}

void encode_settings(const rccl::MotionSettings& s, rccx_net_MotionRequest& r) noexcept {
  r.mode = static_cast<std::uint8_t>(s.mode);
  r.translation_m_per_s = s.translation_m_per_s;
  r.rotation_rad_per_s = s.rotation_rad_per_s;
  r.segment_time_s = s.segment_time_s;
  r.transition_time_s = s.transition_time_s;
  r.configuration = s.configuration;
  r.guard_kind = static_cast<std::uint8_t>(s.guard.kind);
  r.guard_axis = s.guard.axis;
  r.guard_threshold = s.guard.threshold;
  const rccl::Compliance& c = s.compliance;
  r.comply_axes = c.axes;
  for (std::size_t i = 0; i < 6; ++i) {
    r.comply_force[i] = c.force[i];
    r.comply_stiffness[i] = c.stiffness[i];
    r.comply_damping[i] = c.damping[i];
  }
  r.comply_limits[0] = c.max_speed_m_per_s;
  r.comply_limits[1] = c.max_rotation_rad_per_s;
  r.comply_limits[2] = c.max_offset_m;
  r.comply_limits[3] = c.max_offset_rad;
  r.comply_limits[4] = c.max_force_N;
  r.comply_limits[5] = c.max_torque_N_m;
  r.touch = s.may_touch;
}

rccl::MotionSettings decode_settings(const rccx_net_MotionRequest& r) noexcept {
  rccl::MotionSettings s;
  s.mode = r.mode == 1 ? rccl::Mode::cartesian : rccl::Mode::joint;
  s.translation_m_per_s = r.translation_m_per_s;
  s.rotation_rad_per_s = r.rotation_rad_per_s;
  s.segment_time_s = r.segment_time_s;
  s.transition_time_s = r.transition_time_s;
  s.configuration = r.configuration;
  s.guard.kind = r.guard_kind <= 2 ? static_cast<rccl::ForceGuard::Kind>(r.guard_kind)
                                   : rccl::ForceGuard::Kind::none;
  s.guard.axis = r.guard_axis;
  s.guard.threshold = r.guard_threshold;
  rccl::Compliance& c = s.compliance;
  c.axes = r.comply_axes;
  for (std::size_t i = 0; i < 6; ++i) {
    c.force[i] = r.comply_force[i];
    c.stiffness[i] = r.comply_stiffness[i];
    c.damping[i] = r.comply_damping[i];
  }
  c.max_speed_m_per_s = r.comply_limits[0];
  c.max_rotation_rad_per_s = r.comply_limits[1];
  c.max_offset_m = r.comply_limits[2];
  c.max_offset_rad = r.comply_limits[3];
  c.max_force_N = r.comply_limits[4];
  c.max_torque_N_m = r.comply_limits[5];
  s.may_touch = r.touch;
  return s;
}

}  // namespace rccx::net
