"""The GIL and signals while a robot waits: another Python thread keeps (nearly) all its
progress while one waits for a motion in real time; Ctrl-C in a wait (simulated or real time)
halts the robot, ends control and raises KeyboardInterrupt."""

import os
import signal
import threading
import time

import numpy as np
import pytest

from _support import import_rccx

rccx = import_rccx()


def count_while(action):
    """Iterations of a pure-Python loop in another thread while `action` runs, per second."""
    stop = threading.Event()
    box = []

    def counter():
        n = 0
        while not stop.is_set():
            n += 1
        box.append(n)

    t = threading.Thread(target=counter)
    start = time.perf_counter()
    t.start()
    action()
    stop.set()
    t.join()
    return box[0] / (time.perf_counter() - start)


def test_other_thread_keeps_its_progress_while_waiting():
    # 50 ms samples: a Debug (sanitized) build on a busy machine may overrun 10 ms ones.
    with rccx.Robot("puma560", clock="real_time", period=0.05) as arm:
        k = arm.kinematics
        ratios = []
        for trial in range(3):
            baseline = count_while(lambda: time.sleep(1.0))  # sleep releases the GIL
            # a motion lasting about 1 s: joint moves take their time from the speeds
            arm.set_segment_time(1.0)
            target = k.ready + (0.05 if trial % 2 == 0 else 0.0)
            m = arm.move(rccx.joints(f"T{trial}", target))
            waited = count_while(lambda: arm.waitfor(m.end, timeout=10))
            assert arm.happened(m.end)
            ratios.append(waited / baseline)
            if ratios[-1] >= 0.95:
                break
        print("progress kept while waiting:", [f"{r:.3f}" for r in ratios])
        assert max(ratios) >= 0.95, ratios


def interrupt_after(seconds):
    timer = threading.Timer(seconds, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    return timer


@pytest.mark.parametrize("clock", ["simulated", "real_time"])
def test_ctrl_c_in_a_wait_ends_control(clock):
    with rccx.Robot("puma560", clock=clock, period=0.05 if clock == "real_time" else None) as arm:
        k = arm.kinematics
        arm.set_velocity(0.01, 0.05)  # slow: the motion takes many seconds
        arm.move(rccx.joints("FAR", k.ready + np.array([0.5, -0.3, 0.3, 0.5, 0.5, 0.5])))
        arm.dwell(1000.0)
        timer = interrupt_after(0.3)
        start = time.perf_counter()
        with pytest.raises(KeyboardInterrupt):
            arm.waitfor(arm.completed())
        timer.join()
        assert time.perf_counter() - start < 5.0
        assert not arm.controlling
        with pytest.raises(rccx.MotionError):
            arm.move(arm.park)  # no control: nothing queued
        if clock != "simulated":
            return
        # control can start again
        arm.start()
        assert arm.controlling
        q = arm.q.copy()
        assert arm.wait_for(0.2) is None
        np.testing.assert_allclose(arm.q, q, atol=1e-3)  # it stays where it stopped
