// The trajectory generator (thesis 2.4.2, RCCL's setpoint): the RTC control function that turns
// the queue of motion requests into one joint setpoint per sample.
//
// Segments run in joint mode (joints interpolated linearly between the solved end points) or in
// Cartesian mode (the tool frame F = T6 TOOL moves on a straight line, F(t) = G(t) D(r): G the
// goal, re-evaluated every sample so that a moving goal is tracked, D(r) Paul's drive transform
// from the start, expressed in the goal's frame, to the goal; the inverse kinematics solved
// every sample in the configuration the segment started in). A Cartesian segment from rest
// onto a moving goal keeps its start where the arm stood: the goal's displacement since the
// segment began is taken back in proportion to 1 - r (a start riding on the goal would have to
// move at the goal's speed at once; a goal that turns still turns the start).
//
// Between consecutive segments, and when the arm starts from rest or comes to rest, a
// transition of 2 tau seconds centred on the via point keeps position and velocity continuous:
//   - joint coordinates on straight lines (joint mode, rest): Paul's quartic (paul_transition),
//     which stays inside the corner it cuts, so a joint never passes its end points;
//   - a Cartesian segment starting from or ending at rest: Paul's quartic on the drive fraction
//     r, so the tool stays on its line;
//   - two Cartesian segments: the blend of Lloyd and Hayward (1993), (1 - s) F1(t) + s F2(t)
//     with s the quintic smoothstep, of both segments extended past their ends, which stays
//     continuous when either goal moves; a joint-mode segment next to a Cartesian one: the same
//     blend of joint vectors, each segment continued past its ends on its joint-space tangent.
//     Both carry a correction, (v2 - v1) 2 tau w(u), that makes them Paul's quartic when the
//     segments are lines: the velocity passes from one segment's to the other's without the
//     16 % overshoot of the plain blend (which passed a joint's top speed when a fast joint move
//     followed a Cartesian one). A tool blend that cannot be solved or kept within the bounds
//     (its poses near a singularity) falls back to the joint blend.
//
// Slowing down instead of failing (the way Lloyd and Hayward's generator does): nothing is
// planned from estimates alone. Every transition is sampled as the loop will run it (its sample
// times, goals predicted at each one - a moving goal's velocity included - and the segments
// either side), and while a joint would pass its acceleration bound the transition is
// lengthened (and the next segment with it, when it must), while one would pass
// kTransitionSpeedFraction of its top speed the next segment is slowed (its velocity scales as
// 1 / T); the segment now running is never changed, and its room bounds the transition. Every
// Cartesian segment is sampled along its line (T / 1024, and every period near both ends; then
// every period, as the loop will run it) and lengthened as a whole until its joints keep within
// kPlanningSpeedFraction of their top speeds and kPlanningAccelerationFraction of their bounds.
// The planned setpoints then keep every joint within its top speed and within its acceleration
// bound times 1 + kAccelerationTolerance. A motion fails, before it starts, only when no
// slower timing helps: a line through a singularity (a joint would jump), one that leaves the
// workspace anywhere along it, one that would turn a joint past its limit, one that even
// 20 times slower would pass a bound ("too close to a singularity": the time is stretched
// uniformly, so a line that grazes a singularity near one end would otherwise crawl for
// minutes); the message says which. The sample loop's guards (top speed, twice the acceleration
// bound, limits) stay as the last defence and stop the arm smoothly with their own message.
//
// The generator owns the two lock-free queues between the planning level and the loop:
// requests in, events out. Nothing in step() allocates, locks or throws.
#pragma once

#include "rccx/rccl/trajectory/generator.hpp"
#include "rccx/rccl/trajectory/requests.hpp"
