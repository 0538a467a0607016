// Positions and settings on the wire (src/rccx/net/codec.hpp): every term kind crosses and
// comes back as the same equation; what cannot cross is refused saying how to name it.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "rccx/net/codec.hpp"
#include "rccx/rccl/transforms.hpp"

using namespace rccx;

namespace {

math::Transform pose(double x, double y, double z, double angle) {
  math::Transform t = math::Transform::rotation({0.2, 0.3, 0.9}, angle);
  t.p = {x, y, z};
  return t;
}

double distance(const math::Transform& a, const math::Transform& b) {
  double d = (a.p - b.p).norm();
  d += (a.R.n - b.R.n).norm() + (a.R.o - b.R.o).norm() + (a.R.a - b.R.a).norm();
  return d;
}

/// Resolves every functional kind to a constant whose value says which it was.
rccl::TransformPtr resolve(net::TermKind k, std::string_view name) {
  const double code = static_cast<double>(k);
  return rccl::constant(std::string(name) + "_resolved", pose(code, 0, 0, 0));
}

/// `r` through Cyclone's own CDR (what crosses the wire) and back into a sample Cyclone fills
/// as a reader's take does (its sequences allocated by Cyclone, freed here).
struct Wire {
  std::vector<unsigned char> bytes;
  rccx_net_MotionRequest back{};
  explicit Wire(const rccx_net_MotionRequest& r) {
    dds_ostream_t os;
    dds_ostream_init(&os, 0, 1);  // XCDR1: the types are final
    (void)dds_stream_write(&os, reinterpret_cast<const char*>(&r),
                           rccx_net_MotionRequest_desc.m_ops);
    bytes.assign(os.m_buffer, os.m_buffer + os.m_index);
    dds_ostream_fini(&os);
    dds_istream_t is;
    dds_istream_init(&is, static_cast<std::uint32_t>(bytes.size()), bytes.data(), 1);
    (void)dds_stream_read(&is, reinterpret_cast<char*>(&back), rccx_net_MotionRequest_desc.m_ops);
  }
  ~Wire() { dds_sample_free(&back, &rccx_net_MotionRequest_desc, DDS_FREE_CONTENTS); }
  Wire(const Wire&) = delete;
  Wire& operator=(const Wire&) = delete;
};

}  // namespace

TEST(NetCodec, PosesRoundTripExactly) {
  const math::Transform t = pose(0.1, -0.2, 0.3, 0.7);
  rccx_net_Pose p{};
  net::to_pose(t, p);
  EXPECT_EQ(distance(net::from_pose(p), t), 0.0);
  // Row-major: r[1] is the first row's o column.
  EXPECT_EQ(p.r[1], t.R.o.x);
  EXPECT_EQ(p.r[3], t.R.n.y);
}

TEST(NetCodec, EveryTermKindCrossesAndTheEquationIsTheSame) {
  auto base = rccl::constant("BASE", pose(0.1, 0, 0, 0.3));
  auto grip = rccl::hold("GRIP", pose(0, 0, 0.05, 0.1));
  auto tool = rccl::constant("TOOL", pose(0, 0, 0.1, 0));
  auto leader = rccl::functional(
      "PUMA_TOOL", [](const rccl::SampleContext&) { return math::Transform::identity(); });
  leader->set_reference("frame:puma");
  auto conv = rccl::functional(
      "CONV", [](const rccl::SampleContext&) { return math::Transform::identity(); });
  conv->set_reference("function:conveyor");
  auto cam = rccl::functional(
      "CAM", [](const rccl::SampleContext&) { return math::Transform::identity(); });
  cam->set_reference("stream:camera");
  const auto p =
      rccl::Position::make("GOAL", {base, rccl::t6(), tool, grip}, {leader, conv, cam}, tool);
  net::RequestSample sample;
  net::encode_position(*p, sample);
  // Through the wire's bytes: what the serve decodes is what Cyclone deserialized.
  const Wire wire(sample.msg);
  const rccx_net_MotionRequest& r = wire.back;
  ASSERT_EQ(r.lhs._length, 4U);
  ASSERT_EQ(r.rhs._length, 3U);
  EXPECT_EQ(r.tool, 2);
  EXPECT_EQ(r.lhs._buffer[0].kind, static_cast<std::uint8_t>(net::TermKind::constant));
  EXPECT_EQ(r.lhs._buffer[1].kind, static_cast<std::uint8_t>(net::TermKind::t6));
  EXPECT_EQ(r.lhs._buffer[3].kind, static_cast<std::uint8_t>(net::TermKind::hold));
  EXPECT_EQ(r.rhs._buffer[0].kind, static_cast<std::uint8_t>(net::TermKind::frame));
  EXPECT_STREQ(r.rhs._buffer[0].name, "puma");
  EXPECT_EQ(r.rhs._buffer[1].kind, static_cast<std::uint8_t>(net::TermKind::function));
  EXPECT_STREQ(r.rhs._buffer[1].name, "conveyor");
  EXPECT_EQ(r.rhs._buffer[2].kind, static_cast<std::uint8_t>(net::TermKind::stream));
  EXPECT_STREQ(r.rhs._buffer[2].name, "camera");

  const auto back = net::decode_position(r, resolve);
  EXPECT_EQ(back->name(), "GOAL");
  ASSERT_EQ(back->lhs().size(), 4U);
  ASSERT_EQ(back->rhs().size(), 3U);
  EXPECT_EQ(back->lhs()[0]->kind(), rccl::TransformKind::constant);
  EXPECT_EQ(distance(back->lhs()[0]->value(), base->value()), 0.0);
  EXPECT_EQ(back->lhs()[1]->kind(), rccl::TransformKind::t6);
  EXPECT_EQ(back->lhs()[3]->kind(), rccl::TransformKind::hold);
  EXPECT_EQ(distance(back->lhs()[3]->value(), grip->value()), 0.0);
  EXPECT_EQ(back->tool_transform(), back->lhs()[2]);
  // The functional terms came from the resolver, by kind and name.
  EXPECT_EQ(back->rhs()[0]->name(), "puma_resolved");
  EXPECT_EQ(back->rhs()[0]->value().p.x, static_cast<double>(net::TermKind::frame));
  EXPECT_EQ(back->rhs()[1]->name(), "conveyor_resolved");
  EXPECT_EQ(back->rhs()[2]->value().p.x, static_cast<double>(net::TermKind::stream));
  EXPECT_EQ(back->describe(),
            "GOAL: BASE T6 TOOL GRIP = puma_resolved conveyor_resolved "
            "camera_resolved (tool TOOL)");
}

TEST(NetCodec, AHoldCrossesWithTheValueItHasWhenSent) {
  auto h = rccl::hold("H", pose(0.1, 0.1, 0.1, 0));
  const auto p = rccl::Position::make("P", {rccl::t6()}, {h});
  h->set(pose(0.2, 0.2, 0.2, 0.5));
  net::RequestSample r;
  net::encode_position(*p, r);
  const Wire wire(r.msg);
  const auto back = net::decode_position(wire.back, resolve);
  EXPECT_EQ(distance(back->rhs()[0]->value(), pose(0.2, 0.2, 0.2, 0.5)), 0.0);
}

TEST(NetCodec, AJointPositionRoundTrips) {
  const auto p = rccl::Position::joints("park", kin::JointVector{0.1, -0.2, 0.3, 0, 0.5, -0.6});
  net::RequestSample r;
  net::encode_position(*p, r);
  const Wire wire(r.msg);
  const auto back = net::decode_position(wire.back, resolve);
  ASSERT_TRUE(back->in_joints());
  ASSERT_EQ(back->joint_values().size(), 6U);
  for (std::size_t j = 0; j < 6; ++j) EXPECT_EQ(back->joint_values()[j], p->joint_values()[j]);
}

TEST(NetCodec, AFunctionalTransformWithoutANameIsRefusedSayingHowToNameIt) {
  auto f = rccl::functional("WOBBLE",
                            [](const rccl::SampleContext&) { return math::Transform::identity(); });
  const auto p = rccl::Position::make("P", {rccl::t6()}, {f});
  net::RequestSample r;
  r.add_lhs().kind = 42;  // bad input changes nothing
  try {
    net::encode_position(*p, r);
    FAIL() << "an unnamed functional transform was encoded";
  } catch (const net::CodecError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("WOBBLE"), std::string::npos) << m;
    EXPECT_NE(m.find("set_reference(\"function:"), std::string::npos) << m;
    EXPECT_NE(m.find("tool_frame"), std::string::npos) << m;
  }
  ASSERT_EQ(r.msg.lhs._length, 1U);
  EXPECT_EQ(r.msg.lhs._buffer[0].kind, 42);
  f->set_reference("gizmo:x");
  EXPECT_THROW(net::encode_position(*p, r), net::CodecError);
}

TEST(NetCodec, SettingsRoundTrip) {
  rccl::MotionSettings s;
  s.mode = rccl::Mode::cartesian;
  s.translation_m_per_s = 0.05;
  s.rotation_rad_per_s = 0.7;
  s.segment_time_s = 1.5;
  s.transition_time_s = 0.3;
  s.configuration = 3;
  s.guard.kind = rccl::ForceGuard::Kind::along;
  s.guard.axis = 1;
  s.guard.threshold = -4.0;
  s.compliance.axes = 5;
  s.compliance.force[2] = 3.0;
  s.compliance.max_offset_m = 0.01;
  s.may_touch = 6;
  rccx_net_MotionRequest r{};
  net::encode_settings(s, r);
  const rccl::MotionSettings b = net::decode_settings(r);
  EXPECT_EQ(b.mode, s.mode);
  EXPECT_EQ(b.translation_m_per_s, 0.05);
  EXPECT_EQ(b.rotation_rad_per_s, 0.7);
  EXPECT_EQ(b.segment_time_s, 1.5);
  EXPECT_EQ(b.transition_time_s, 0.3);
  EXPECT_EQ(b.configuration, 3);
  EXPECT_EQ(b.guard.kind, rccl::ForceGuard::Kind::along);
  EXPECT_EQ(b.guard.axis, 1);
  EXPECT_EQ(b.guard.threshold, -4.0);
  EXPECT_EQ(b.compliance.axes, 5);
  EXPECT_EQ(b.compliance.force[2], 3.0);
  EXPECT_EQ(b.compliance.max_offset_m, 0.01);
  EXPECT_EQ(b.may_touch, 6U);
}

TEST(NetCodec, ACopiedRequestOwnsItsTermsAndSendsOnlyThoseItHas) {
  auto base = rccl::constant("BASE", pose(0.1, 0, 0, 0.3));
  const auto p =
      rccl::Position::make("P", {base, rccl::t6()}, {rccl::constant("OBJ", pose(0.4, 0, 0, 0))});
  net::RequestSample a;
  net::encode_position(*p, a);
  const net::RequestSample b = a;  // RemoteArm re-sends a copy: its sequences must be its own
  a.add_rhs().kind = 9;
  EXPECT_NE(b.msg.lhs._buffer, a.msg.lhs._buffer);
  EXPECT_EQ(b.msg.rhs._length, 1U);
  EXPECT_STREQ(b.msg.rhs._buffer[0].name, "OBJ");
  const Wire wire(b.msg);
  EXPECT_EQ(wire.back.rhs._length, 1U);
  EXPECT_STREQ(wire.back.lhs._buffer[0].name, "BASE");

  // On the wire, a request carries the terms it has: an attach (none) is a few hundred bytes,
  // each term about 110 more (its pose). With the 8 + 8 terms and 4 gates as fixed arrays, every
  // request was over 2 kB, whatever it carried.
  const net::RequestSample attach;
  const std::size_t empty = Wire(attach.msg).bytes.size();
  const std::size_t two_and_one = wire.bytes.size();
  EXPECT_LT(empty, 500U);
  EXPECT_GT(two_and_one, empty + 2 * 100);  // BASE and OBJ carry their poses
  EXPECT_LT(two_and_one, empty + 3 * 130);
  std::printf("serialized: attach %zu B, 2 + 1 terms %zu B\n", empty, two_and_one);
}

TEST(NetCodec, AReceivedRequestWithATooLargeToolIndexIsRefused) {
  net::RequestSample r;
  const auto p =
      rccl::Position::make("P", {rccl::t6()}, {rccl::constant("OBJ", pose(0.4, 0, 0, 0))});
  net::encode_position(*p, r);
  r.msg.tool = 1;  // lhs has one term
  EXPECT_THROW((void)net::decode_position(Wire(r.msg).back, resolve), net::CodecError);
}
