"""Driving a robot from Python: the washer written in Python (python/examples/washer.py) writes
the same sample log as the C++ washer (examples/04_washer) in simulated time; a stream-fed goal
is reached where forward kinematics says; bad arguments raise and leave the robot as it was."""

import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from _support import REQUIRED, import_rccx

rccx = import_rccx()

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"
WASHER = os.environ.get("RCCX_WASHER", "")


def rows(path):
    """The log's lines; the header's comment lines (#) apart from the data."""
    lines = pathlib.Path(path).read_text().splitlines()
    return [x for x in lines if x.startswith("#")], [x for x in lines if not x.startswith("#")]


def test_python_washer_log_equals_cpp(tmp_path):
    if not WASHER:
        if REQUIRED:
            pytest.fail("RCCX_WASHER is not set: ctest names examples/04_washer")
        pytest.skip("RCCX_WASHER (the C++ washer, examples/04_washer) is not set")
    env = dict(os.environ)
    env["RCCX_LOG"] = str(tmp_path / "cpp.csv")
    c = subprocess.run([WASHER], env=env, capture_output=True, text=True, timeout=240, check=False)
    assert c.returncode == 0, c.stderr
    env["RCCX_LOG"] = str(tmp_path / "py.csv")
    p = subprocess.run([sys.executable, str(EXAMPLES / "washer.py")], env=env,
                       capture_output=True, text=True, timeout=240, check=False)
    assert p.returncode == 0, p.stdout + p.stderr
    cpp_head, cpp_rows = rows(tmp_path / "cpp.csv")
    py_head, py_rows = rows(tmp_path / "py.csv")
    assert len(cpp_rows) > 500  # 13 segments of the Microbo at 28 ms
    assert len(py_rows) == len(cpp_rows)
    for i, (a, b) in enumerate(zip(cpp_rows, py_rows)):
        assert a == b, f"row {i} differs:\n C++    {a}\n Python {b}"
    assert cpp_head == py_head
    # Both print the same rounds.
    rounds = [x for x in c.stdout.splitlines() if x.startswith("round")]
    assert rounds == [x for x in p.stdout.splitlines() if x.startswith("round")]


def test_stream_goal_reached():
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        goal = k.forward(k.ready + np.array([0.2, -0.1, 0.1, 0.2, 0.2, 0.1]))
        s = rccx.stream("TARGET", k.forward(k.ready))
        p = rccx.position("FOLLOW", rccx.t6() == s)
        s.put(goal)
        arm.set_mode("cartesian")
        m = arm.move(p)
        assert arm.waitfor(m.end, timeout=30) == "reached"
        arm.wait_for(0.5)
        np.testing.assert_allclose(k.forward(arm.q), goal, atol=2e-3)


def test_stream_with_time_and_velocity_moves_the_goal_on():
    # One put(), with the session time the pose is for and its velocity: the arm follows the
    # goal the stream extrapolates at each setpoint, measured (forward kinematics of arm.q),
    # until max_extrapolation past the put's time, where the goal stands.
    v_m_per_s, max_s = 0.02, 1.5
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        start = k.forward(k.ready)
        s = rccx.stream("TARGET", start, max_extrapolation=max_s)
        assert s.max_extrapolation == max_s
        at_s = arm.time
        s.put(start, at=at_s, velocity=[0.0, v_m_per_s, 0.0, 0.0, 0.0, 0.0])
        arm.set_mode("cartesian")
        m = arm.move(rccx.position("FOLLOW", rccx.t6() == s))
        assert arm.waitfor(m.end, timeout=30) == "reached"
        lags_m = []
        while arm.time < at_s + max_s - 0.1:
            arm.wait_for(0.1)
            y_goal = start[1, 3] + v_m_per_s * (arm.time - at_s)
            lags_m.append(abs(k.forward(arm.q)[1, 3] - y_goal))
        assert len(lags_m) >= 5 and max(lags_m) < 2e-3, lags_m  # moving: about 3 samples behind
        arm.wait_for(0.5)
        here = k.forward(arm.q)
        np.testing.assert_allclose(here[:3, 3], start[:3, 3] + [0.0, v_m_per_s * max_s, 0.0],
                                   atol=5e-4)
        arm.wait_for(0.2)
        # The goal stands: the wrist stays (its orientation still settles, about 1e-4 rad).
        np.testing.assert_allclose(k.forward(arm.q)[:3, 3], here[:3, 3], atol=1e-5)


def test_motion_events_and_report():
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        there = rccx.joints("THERE", k.ready + 0.1)
        m = arm.move(there)
        assert isinstance(m, rccx.Motion) and m.id == 1
        assert not arm.happened(m.end)
        assert arm.waitfor(m.start) == "reached"
        assert arm.waitfor(m.end) == "reached"
        np.testing.assert_allclose(arm.q, k.ready + 0.1, atol=1e-3)
        kinds = [(e["kind"], e["id"]) for e in arm.take_events()]
        assert ("started", 1) in kinds and ("ended", 1) in kinds
        r = arm.report(m)
        assert r["id"] == 1 and r["end"] > r["start"] >= 0 and not r["failed"]
        assert arm.failures() == []
        d = arm.dwell(0.3)
        assert arm.waitfor(arm.completed()) == "reached"
        assert arm.report(d)["id"] == d.id == 2
        assert arm.waitfor(arm.ended(there)) == "reached"
        # a timeout in simulated time runs exactly that much
        t0 = arm.time
        far = arm.move(rccx.joints("FAR", k.ready - 0.5))
        assert arm.waitfor(far.end, timeout=0.05) == "timeout"
        assert arm.time - t0 < 0.2
        arm.halt()
        assert arm.waitfor(far.end) == "failed"
        assert arm.failures()[0]["id"] == far.id


def test_bad_arguments_leave_robot_unchanged():
    with pytest.raises(KeyError, match="puma560"):
        rccx.Robot("no_such_robot")
    with pytest.raises(ValueError, match="clock"):
        rccx.Robot("puma560", clock="sundial")
    with rccx.Robot("puma560") as arm:
        k = arm.kinematics
        q0 = arm.q.copy()
        before = arm.last_queued
        far = np.eye(4)
        far[:3, 3] = [5.0, 0.0, 0.0]  # 5 m away: out of reach
        with pytest.raises(rccx.MotionError, match="reach") as e:
            arm.move(rccx.position("FAR", rccx.t6() == rccx.const("FAR", far)))
        assert isinstance(e.value, RuntimeError)
        with pytest.raises(rccx.MotionError):
            arm.move(rccx.joints("WRONG", [0.0, 0.0]))  # 2 joint values for a 6-axis arm
        with pytest.raises(rccx.MotionError, match="velocit"):
            arm.set_velocity(-1.0, 1.0)
        with pytest.raises(rccx.MotionError):
            arm.set_velocity(float("nan"), 1.0)
        with pytest.raises(ValueError, match="mode"):
            arm.set_mode("sideways")
        with pytest.raises(TypeError):
            arm.move(np.eye(4))
        with pytest.raises(ValueError, match="timeout"):
            arm.waitfor(arm.completed(), timeout=-1)
        assert arm.last_queued == before and arm.mode == "joint"
        assert arm.wait_for(0.1) is None
        np.testing.assert_allclose(arm.q, q0, atol=1e-9)
        assert arm.controlling
    # closed: calls raise, nothing crashes
    with pytest.raises(rccx.SessionError, match="closed"):
        arm.move(arm.park)
    assert not arm.controlling
