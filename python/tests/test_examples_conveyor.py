"""python/examples/conveyor.py (the belt a stream fed from Python) against examples/05_conveyor
(the belt a C++ function of the sample's time): fed sample by sample in simulated time, the
same segments and the same tracking figures as the C++ (within its 2 mm). In real time a
Python thread feeds the belt and the lag stays within its bound."""

import pytest

from _examples_support import check_help, cpp_example, number_after, run_cpp, run_python
from _support import import_rccx

rccx = import_rccx()


def figures(out):
    return {"max": number_after(out, r"the object: max"),
            "mean": number_after(out, r"mean"),
            "settled": number_after(out, r"after the catch and on: at most"),
            "samples": number_after(out, r"tracking for [\d.]+ s \(")}


def test_tracks_as_cpp():
    c = run_cpp(cpp_example("RCCX_EX_CONVEYOR"))
    assert c.returncode == 0, c.stdout + c.stderr
    p = run_python("conveyor")
    assert p.returncode == 0, p.stdout + p.stderr
    fp = figures(p.stdout)
    assert fp["samples"] >= 250 and fp["max"] <= 2.0
    # Fed with the belt's pose for each setpoint's time, the stream is the C++ function: the
    # same segment table and figures to the printed digit.
    table_c, table_p = c.stdout.split("\n seg", 1)[1], p.stdout.split("\n seg", 1)[1]
    assert "tracking for" in table_c and table_p == table_c
    assert "FAILED" not in p.stdout


def test_thread_feed_real_time():
    # Real time on a shared machine: the thread's puts may come late (a looser bound than the
    # example's 2 mm), and a session that overran its period ends control: that is the
    # machine's load, not the program's (said, and skipped).
    # A feeding thread starved by the load is run again, up to three times, and skipped, saying
    # so, when every run missed: the tracking bound missed ("tracking:"), or, starved for longer
    # than the stream extrapolates its poses (0.25 s), the goal jumped by the belt's travel
    # meanwhile, which the generator's guards refuse ("jumped"). The
    # simulated-time tests judge the stream itself, to the printed digit.
    starved = ("tracking:", "jumped")
    for attempt in range(3):
        p = run_python("conveyor", "--clock", "real_time", "--bound-mm", 4)
        if p.returncode != 0 and ("overrun" in p.stderr or "session_ended" in p.stderr):
            pytest.skip(f"real time under load: {p.stderr.strip().splitlines()[-1]}")
        if p.returncode == 0 or not any(s in p.stderr for s in starved):
            break
    else:
        reason = next(line for line in p.stderr.splitlines() if any(s in line for s in starved))
        pytest.skip(f"real time under load, 3 runs: the feeding thread starved ({reason})")
    assert p.returncode == 0, p.stdout + p.stderr
    assert "fed by a thread" in p.stdout
    assert figures(p.stdout)["samples"] >= 150


def test_put_every_10_samples_with_velocity_tracks_as_cpp():
    # Poses put every 10th sample with their time and velocity: the stream moves each on to the
    # setpoint's time, so the arm tracks as when fed every sample (the C++ function's figures).
    c = run_cpp(cpp_example("RCCX_EX_CONVEYOR"))
    p = run_python("conveyor", "--put-every", 10)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "every 10 samples" in p.stdout
    assert p.stdout.split("\n seg", 1)[1] == c.stdout.split("\n seg", 1)[1]


def test_bare_poses_every_10_samples_jump():
    # The same puts without time and velocity: the goal stands for 10 samples, then jumps by the
    # belt's travel meanwhile (4 mm); the generator's guard refuses the jump and says why.
    p = run_python("conveyor", "--put-every", 10, "--no-velocity")
    assert p.returncode == 1
    assert "the goal of ON_BELT jumped 4.0 mm in a sample" in p.stderr, p.stdout + p.stderr


def test_bound_can_fail():
    p = run_python("conveyor", "--bound-mm", "0.001")
    assert p.returncode == 1 and "tracking:" in p.stderr


def test_help():
    check_help("conveyor")


def test_real_time_robot_knows_its_joints_at_once():
    """rccx.Robot(clock="real_time") returns once a sample has been read: q and the arm's
    configuration are known to the first move (which would otherwise take the arm as not yet
    anywhere)."""
    with rccx.Robot("puma560", clock="real_time") as arm:
        k = arm.kinematics
        assert arm.q.shape == (k.dof,) and arm.time > 0
        assert k.configuration_of(arm.q) is not None
