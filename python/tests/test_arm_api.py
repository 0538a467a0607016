"""The robot API's calls one by one (issue 27), each against what the C++ library documents
(src/rccx/rccl/manipulator.hpp, arm.hpp, trajectory/requests.hpp, src/rccx/cell/cell.hpp,
docs/RCCL.md) or against geometry: nextmove, set_hand, halt, dwell, set_configuration, the
segment and transition times, the report's and the events' fields, waitfor's timeouts, a cell's
joint start (together), touching, and a cell's errors. Simulated time throughout but for one
real-time timeout: deterministic."""

import pathlib
import re
import time

import numpy as np
import pytest

from _support import import_rccx, skip_if_control_ended

rccx = import_rccx()

ROOT = pathlib.Path(__file__).resolve().parents[2]
CELL = str(ROOT / "cells" / "cvarl.json")


def cpp_fields(struct):
    """The data members of a C++ struct of src/rccx/rccl/trajectory/requests.hpp."""
    text = (ROOT / "src/rccx/rccl/trajectory/requests.hpp").read_text()
    body = re.search(r"struct " + struct + r" \{(.*?)\n\};", text, re.S).group(1)
    return re.findall(r"^\s+[\w:<>, ]+?\s(\w+)(?: = [^;]*)?;", body, re.M)


def python_name(field):
    """A C++ field's name in Python: its unit suffix dropped (start_s -> start)."""
    return re.sub(r"_(s|m|rad|m_per_s)$", "", field)


def events_of(arm, motion_id):
    return [e for e in arm.take_events() if e["id"] == motion_id]


# --- nextmove, halt, dwell, the hand ----------------------------------------------------------


def test_nextmove_ends_the_running_motion_where_the_arm_is():
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        arm.set_velocity(0.05, 0.2)  # slow: motion A would take seconds
        goal_a, goal_b = k.ready + 0.5, k.ready - 0.1
        a = arm.move(rccx.joints("A", goal_a))
        b = arm.move(rccx.joints("B", goal_b))
        assert arm.waitfor(a.start) == "reached"
        arm.wait_for(0.5)
        q1, t1 = arm.q.copy(), arm.time
        arm.nextmove()
        assert arm.waitfor(a.end) == "reached"
        # A ended within a few samples, close to where the arm was, far from its goal.
        ra = arm.report(a)
        assert ra["end"] - t1 < 0.1 and ra["end"] - ra["start"] < ra["duration"]
        assert np.abs(arm.q - q1).max() < 0.01
        assert np.abs(arm.q - goal_a).max() > 0.3
        ended = [e for e in arm.take_events() if e["kind"] == "ended" and e["id"] == a.id]
        assert ended and ended[0]["message"] == "ended by nextmove"  # kNextmoveText
        # The queue goes on from there: B runs to its goal.
        assert arm.waitfor(b.end) == "reached"
        assert arm.report(b)["start"] >= ra["end"]
        np.testing.assert_allclose(arm.q, goal_b, atol=2e-3)
        assert arm.failures() == []
        # With no motion running, nextmove does nothing.
        arm.nextmove()
        assert arm.wait_for(0.1) is None
        np.testing.assert_allclose(arm.q, goal_b, atol=2e-3)


def test_halt_cancels_the_queue_and_failures_say_so():
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        ms = [arm.move(rccx.joints(f"H{i}", k.ready + 0.2 * (i + 1))) for i in range(3)]
        arm.waitfor(ms[0].start)
        arm.wait_for(0.2)
        arm.halt()
        assert arm.waitfor(arm.completed()) in ("reached", "failed")
        assert [arm.waitfor(m.end, timeout=0) for m in ms] == ["failed"] * 3
        f = arm.failures()
        assert [(e["kind"], e["id"]) for e in f] == [("failed", ms[0].id),
                                                    ("cancelled", ms[1].id),
                                                    ("cancelled", ms[2].id)]
        assert "halted" in f[0]["message"]
        assert all(arm.report(m)["failed"] for m in ms[:1])
        # At rest where it stopped, short of the first goal.
        arm.wait_for(0.5)
        q = arm.q.copy()
        arm.wait_for(0.5)
        assert np.abs(arm.q - q).max() < 1e-3  # the servo settling, no motion
        assert np.abs(q - (k.ready + 0.2)).max() > 0.05
        # A halt leaves the arm in control: the next motion runs.
        m = arm.move(arm.park)
        assert arm.waitfor(m.end) == "reached"
        np.testing.assert_allclose(arm.q, k.ready, atol=2e-3)


def test_dwell_keeps_the_arm_still_for_its_time(tmp_path):
    # docs/RCCL.md "stop(ms)": still for ms rounded up to whole samples, at least 3 samples.
    log = tmp_path / "dwell.csv"
    with rccx.Robot("puma560", log=str(log)) as arm:
        k = arm.kinematics
        period = arm.period
        arm.set_mode("cartesian")
        T = k.forward(k.ready)
        stills = {}
        for i, dwell_s in enumerate((0.3, 0.005)):
            T1 = T.copy()
            T1[:3, 3] += [0.04 * (1 - 2 * (i % 2)), 0.0, 0.0]
            arm.move(rccx.position(f"P{i}", rccx.t6() == rccx.const(f"P{i}", T1)))
            d = arm.dwell(dwell_s)
            arm.move(rccx.position(f"Q{i}", rccx.t6() == rccx.const(f"Q{i}", T)))
            assert arm.waitfor(arm.completed()) == "reached"
            stills[dwell_s] = (d.id, max(np.ceil(round(dwell_s / period, 6)), 3) * period)
    samples = rccx.log.load(log).samples
    moving = np.any(np.abs(np.diff(samples["commanded"], axis=0)) > 1e-12, axis=1)
    for dwell_s, (dwell_id, expected) in stills.items():
        # the dwell's samples and the still run around them
        rows = np.flatnonzero(samples["segment"] == dwell_id)
        assert len(rows) > 0
        lo, hi = rows[0], rows[-1]
        while lo > 0 and not moving[lo - 1]:
            lo -= 1
        while hi < len(moving) and not moving[hi]:
            hi += 1
        still = (hi - lo) * period
        assert still == pytest.approx(expected, abs=period + 1e-9), (dwell_s, still)


def test_set_hand_reaches_the_hardware_a_sample_on():
    with rccx.Robot("puma560") as arm:
        assert arm.hand_closed is False
        arm.set_hand(True)
        assert arm.hand_closed is False  # simulated time: no sample has run yet
        arm.wait_for(3 * arm.period)
        assert arm.hand_closed is True
        arm.set_hand(False)
        arm.wait_for(3 * arm.period)
        assert arm.hand_closed is False


# --- settings --------------------------------------------------------------------------------


@pytest.mark.parametrize("segment,transition", [(0.6, 0.2), (1.0, 0.4)])
def test_segment_and_transition_times(segment, transition):
    # settime: the segment lasts `segment`; the transitions (2 tau) straddle its ends, so a
    # motion from rest to rest runs from -tau to T + tau.
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        arm.set_segment_time(segment)
        arm.set_transition_time(transition)
        m = arm.move(rccx.joints("A", k.ready + 0.1))
        assert arm.waitfor(m.end) == "reached"
        r = arm.report(m)
        assert r["duration"] == pytest.approx(segment, abs=1e-9)
        assert r["end"] - r["start"] == pytest.approx(segment + transition, abs=arm.period + 1e-9)
        # 0: from the speeds (a short move at the default speeds is faster than asked above)
        arm.set_segment_time(0.0)
        m = arm.move(rccx.joints("B", k.ready))
        assert arm.waitfor(m.end) == "reached"
        assert arm.report(m)["duration"] != pytest.approx(segment)
        with pytest.raises(rccx.MotionError):
            arm.set_transition_time(0.0)  # > 0
        with pytest.raises(rccx.MotionError):
            arm.set_segment_time(-1.0)


def test_set_configuration_moves_into_the_configuration_asked():
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        T = k.forward(k.ready + np.array([0.1, -0.2, 0.1, 0.3, -0.3, 0.2]))
        goal = rccx.position("G", rccx.t6() == rccx.const("G", T))
        here = k.configuration_of(arm.q)
        reachable = [c for c in k.configuration_names if c != here
                     and _reaches(k, T, c)]
        assert reachable, "no other configuration reaches the goal"
        for c in (reachable[0], here):
            arm.set_configuration(c)
            m = arm.move(goal)
            assert arm.waitfor(m.end, timeout=60) == "reached", arm.failures()
            arm.wait_for(0.3)
            assert k.configuration_of(arm.q) == c
            np.testing.assert_allclose(arm.q, k.inverse(T, configuration=c), atol=2e-3)
            np.testing.assert_allclose(k.forward(arm.q), T, atol=2e-3)
        with pytest.raises(rccx.MotionError, match=r"no configuration 'xyz'.*lun"):
            arm.set_configuration("xyz")


def _reaches(k, T, c):
    try:
        k.inverse(T, configuration=c)
        return True
    except rccx.UnreachableError:
        return False


# --- what happened ---------------------------------------------------------------------------


def test_report_fields_are_the_cpp_segment_report():
    fields = cpp_fields("SegmentReport")
    assert "max_measured_path_error_m" in fields and len(fields) >= 10
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        v = 0.1
        arm.set_mode("cartesian")
        arm.set_velocity(v, 1.0)
        T = k.forward(k.ready)
        T2 = T.copy()
        step = np.array([0.1, 0.0, -0.05])
        T2[:3, 3] += step
        m = arm.move(rccx.position("C", rccx.t6() == rccx.const("C", T2)))
        assert arm.waitfor(m.end) == "reached"
        r = arm.report(m)
        assert set(r) == {python_name(f) for f in fields}
        assert r["id"] == m.id and r["mode"] == "cartesian" and r["failed"] is False
        # Geometry: a straight line of |step| at v; its straight part the segment less a
        # transition, in samples; the tool's peak speed v; the path straight.
        assert r["duration"] == pytest.approx(np.linalg.norm(step) / v, rel=1e-3)
        assert r["end"] - r["start"] == pytest.approx(r["duration"] + 0.2, abs=arm.period)
        assert abs(r["straight_samples"] - (r["duration"] - 0.2) / arm.period) <= 1
        assert r["peak_tool_speed"] == pytest.approx(v, rel=1e-3)
        assert r["max_commanded_path_error"] < 1e-6
        assert 0 <= r["max_measured_path_error"] < 1e-3
        assert 0 <= r["max_approach_error"] < 1e-3
        np.testing.assert_allclose(k.forward(arm.q)[:3, 3], T2[:3, 3], atol=1e-3)
        # A joint motion reports its times only.
        arm.set_mode("joint")
        j = arm.move(arm.park)
        arm.waitfor(j.end)
        rj = arm.report(j)
        assert rj["mode"] == "joint" and rj["straight_samples"] == 0


def test_take_events_in_order():
    fields = cpp_fields("MotionEvent")
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        ms = [arm.move(rccx.joints(f"E{i}", k.ready + 0.05 * (i + 1))) for i in range(3)]
        ms.append(arm.dwell(0.1))
        assert arm.waitfor(arm.completed()) == "reached"
        events = arm.take_events()
        assert arm.take_events() == []  # taken
        # Every C++ field but the status, its text as message.
        assert set(events[0]) == {"kind", "message"} | set(fields) - {"kind", "status", "text",
                                                                     "t_s"} | {"t"}
        # In the order they happened: each motion starts before it ends and after the one
        # before it started (the transitions overlap the ends of segments); a dwell is never
        # blended (docs/RCCL.md, "stop(ms)"): it starts once the motion before it ended.
        t = [e["t"] for e in events]
        assert t == sorted(t)
        assert sorted((e["kind"], e["id"]) for e in events) == sorted(
            (kind, m.id) for m in ms for kind in ("started", "ended"))
        order = [(e["kind"], e["id"]) for e in events]
        assert [i for kind, i in order if kind == "started"] == [m.id for m in ms]
        for m in ms:
            assert order.index(("started", m.id)) < order.index(("ended", m.id))
        assert order.index(("ended", ms[2].id)) < order.index(("started", ms[3].id))
        # t is the time of the sample it happened in: sample numbers at one period a sample.
        offsets = {round(e["t"] / arm.period - e["sample"], 6) for e in events}
        assert len(offsets) == 1
        for m in ms:
            r = arm.report(m)
            started, ended = [e for e in events if e["id"] == m.id]
            assert started["t"] == pytest.approx(r["start"]) and ended["t"] == pytest.approx(r["end"])


def test_waitfor_timeouts_in_simulated_time():
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        far = arm.move(rccx.joints("FAR", k.ready - 0.4))
        for timeout in (0.35, 0.73, 0.0):  # shorter and longer than a slice (0.1 s), none
            t0 = arm.time
            assert arm.waitfor(far.end, timeout=timeout) == "timeout"
            # exactly that many samples run
            assert arm.time - t0 == pytest.approx(timeout, abs=1e-9)
        assert arm.waitfor(far.end) == "reached"
        t0 = arm.time
        assert arm.waitfor(far.end, timeout=0) == "reached"  # happened: no time passes
        assert arm.time == t0
        with pytest.raises(ValueError, match="timeout"):
            arm.waitfor(far.end, timeout=float("nan"))


def test_waitfor_timeout_in_real_time():
    with rccx.Robot("puma560", clock="real_time", period=0.05) as arm:
        k = arm.kinematics
        arm.set_segment_time(5.0)
        far = arm.move(rccx.joints("FAR", k.ready - 0.4))
        for timeout in (0.05, 0.3):
            start = time.perf_counter()
            w = arm.waitfor(far.end, timeout=timeout)
            elapsed = time.perf_counter() - start
            if w == "session_ended":
                skip_if_control_ended(arm)
            assert w == "timeout"
            assert timeout - 0.005 <= elapsed < timeout + 0.5, (timeout, elapsed)
        arm.halt()
        assert arm.waitfor(far.end, timeout=5) == "failed"


# --- cells -----------------------------------------------------------------------------------


@pytest.mark.parametrize("end_together", [False, True])
def test_together_starts_in_the_same_sample(end_together):
    with rccx.Cell(CELL) as cell:
        cell.start()
        puma, microbo = cell.robot("puma"), cell.robot("microbo")
        kp, km = puma.kinematics, microbo.kinematics
        # The PUMA turns its wrist only (clear of the Microbo), busy first.
        roll = 0.4 * np.eye(kp.dof)[5]
        first = puma.move(rccx.joints("P1", kp.ready + roll))
        tg = cell.together(["puma", "microbo"], end_together=end_together)
        mp = puma.move(rccx.joints("P2", kp.ready - roll), after=tg.when("puma"))
        mm = microbo.move(rccx.joints("M2", km.ready + 0.05 * np.eye(km.dof)[0]),
                          after=tg.when("microbo"))
        assert cell.waitfor([cell.event("puma", mp.end), cell.event("microbo", mm.end)],
                            timeout=60) == "reached"
        rf, rp, rm = puma.report(first), puma.report(mp), microbo.report(mm)
        assert rp["start"] == pytest.approx(rm["start"], abs=1e-9)
        assert rp["start"] >= rf["end"]  # the Microbo waited for the PUMA
        if end_together:
            assert rp["end"] == pytest.approx(rm["end"], abs=1e-9)
        else:  # their own lengths
            assert rp["end"] != pytest.approx(rm["end"], abs=1e-3)
        # Without the joint start, the Microbo's motion starts while the PUMA is busy.
        busy = puma.move(rccx.joints("P3", kp.ready))
        alone = microbo.move(rccx.joints("M3", km.ready))
        assert cell.waitfor([cell.event("puma", busy.end),
                             cell.event("microbo", alone.end)], timeout=60) == "reached"
        assert microbo.report(alone)["start"] < puma.report(busy)["end"] - 0.1
        with pytest.raises(ValueError, match="microbo"):
            cell.together(["puma", "nobody"])
        # Another robot's place in a joint start is refused; nothing is queued.
        tg = cell.together(["puma", "microbo"])
        before = puma.last_queued
        with pytest.raises(rccx.MotionError, match="place 1 is robot microbo's"):
            puma.move(rccx.joints("P4", kp.ready), after=tg.when("microbo"))
        assert puma.last_queued == before


def _down(x, y, z):
    """A world pose at (x, y, z), m, its z axis (the tool's approach) pointing down."""
    T = np.diag([1.0, -1.0, -1.0, 1.0])
    T[:3, 3] = [x, y, z]
    return T


@pytest.mark.parametrize("objects,touched", [(None, "board"), (["board"], "xy_stage"),
                                             (["board", "xy_stage"], None)])
def test_touching_lets_the_tool_reach_those_objects(objects, touched):
    # The Microbo's probe descends onto the board's face (cells/cvarl.json: board_home, the
    # face 0.1016 m up, on the x-y stage): the collision check stops it within the margin of
    # any object its motion may not touch, and names that object.
    with rccx.Cell(CELL) as cell:
        cell.start()
        mb = cell.robot("microbo")
        mb.set_mode("cartesian")
        above = mb.move(cell.world_goal("microbo", "ABOVE", _down(0.02, 0.0, 0.1516)))
        assert mb.waitfor(above.end, timeout=30) == "reached"
        after = cell.touching(objects) if objects else None
        d = mb.move(cell.world_goal("microbo", "DOWN", _down(0.02, 0.0, 0.1016)), after=after)
        result = mb.waitfor(d.end, timeout=30)
        if touched is None:
            assert result == "reached", mb.failures()
            tip = cell.base("microbo") @ mb.kinematics.forward(mb.q) @ cell.tool_transform(
                "microbo").value
            np.testing.assert_allclose(tip[:3, 3], [0.02, 0.0, 0.1016], atol=2e-3)
        else:
            assert result == "failed"
            (f,) = mb.failures()
            assert f["id"] == d.id and "collision stop" in f["message"]
            assert f"object {touched}" in f["message"]


def test_cell_errors_name_what_there_is(tmp_path):
    with rccx.Cell(CELL) as cell:
        for call in (lambda: cell.robot("nobody"), lambda: cell.base("nobody"),
                     lambda: cell.event("nobody", cell.robot("puma").completed()),
                     lambda: cell.tool_frame("nobody"),
                     lambda: cell.world_goal("nobody", "G", np.eye(4))):
            with pytest.raises(ValueError, match=r"nobody.*puma, microbo"):
                call()
        with pytest.raises(ValueError, match=r"bord.*table, xy_stage, board"):
            cell.touching(["bord"])
    with pytest.raises(rccx.CellFileError, match="no_such_cell.json"):
        rccx.Cell(str(tmp_path / "no_such_cell.json"))
    bad = tmp_path / "broken_cell.json"
    bad.write_text('{"name": "broken", "robots": [')
    with pytest.raises(rccx.CellFileError, match="broken_cell.json") as e:
        rccx.Cell(str(bad))
    assert isinstance(e.value, ValueError)
    unknown = tmp_path / "unknown_robot.json"
    unknown.write_text(
        '{"name": "u", "base_period_ms": 10, "robots": [{"name": "r", "robot": "no_such_robot",'
        ' "base": {"xyz_m": [0, 0, 0]}}], "objects": []}')
    with pytest.raises(rccx.CellFileError, match="unknown_robot.json"):
        rccx.Cell(str(unknown))


def test_events_belong_to_their_robot():
    # Motion ids are each arm's own (C++ Motion{id}): another robot's motion's event would name
    # a motion of its own, or none, so it is refused, as are gates of another cell (they point
    # into that cell's ledgers, which need not outlive the motion that waits on them).
    with rccx.Cell(CELL) as cell:
        cell.start()
        puma, microbo = cell.robot("puma"), cell.robot("microbo")
        m = puma.move(rccx.joints("P", puma.kinematics.ready + 0.05))
        mine = microbo.move(rccx.joints("M", microbo.kinematics.ready))
        assert m.id == mine.id == 1  # the same id, two motions
        for call in (lambda: microbo.waitfor(m.end, timeout=1), lambda: microbo.happened(m.start),
                     lambda: microbo.report(m), lambda: cell.event("microbo", m.end),
                     lambda: cell.after("microbo", m.end)):
            with pytest.raises(ValueError, match="robot puma's motion"):
                call()
        assert puma.waitfor(m.end, timeout=10) == "reached"
        assert cell.waitfor(cell.event("microbo", mine.end), timeout=10) == "reached"
        # completed() and ended(p) name no motion: any robot's own
        assert microbo.waitfor(puma.completed(), timeout=1) == "reached"
        with rccx.Robot("puma560") as arm, rccx.Cell(CELL) as other:
            other.start()
            for after in (cell.event("puma", m.end), cell.after("puma", m.end),
                          cell.touching(["board"]), [cell.event("puma", m.end)]):
                with pytest.raises(ValueError, match="another cell"):
                    arm.move(arm.park, after=after)
                with pytest.raises(ValueError, match="another cell"):
                    other.robot("puma").dwell(0.1, after=after)
            assert arm.last_queued == 0 and other.robot("puma").last_queued == 0


def test_bad_arguments_raise_clear_errors():
    with pytest.raises(ValueError, match="period must be > 0"):
        rccx.Robot("puma560", period=0.0)
    with pytest.raises(rccx.SessionError, match="outside"):
        rccx.Robot("puma560", period=1e-6)
    with rccx.Cell(CELL) as cell:
        cell.start()
        puma = cell.robot("puma")
        m = puma.move(rccx.joints("P", puma.kinematics.ready + 0.05))
        for bad in ([m.end], m.end, 5, [cell.event("puma", m.end), None]):
            with pytest.raises(TypeError, match=r"cell\.event\(robot, event\)"):
                cell.waitfor(bad)
        assert cell.waitfor((cell.event("puma", m.end),), timeout=10) == "reached"
