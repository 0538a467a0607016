"""A Python move() to its first setpoint against C++'s (run by run.py; the C++ peer is
bench/move_bench.cpp's BM_MoveToFirstSetpoint, in the Makefile's BENCH_PYTHON_CPP filter).

move_first_setpoint  a simulated PUMA 560 in simulated time (rccx.Robot("puma560"), its usual
                     10 ms period) goes back and forth between two Cartesian goals (T6 == G, G a
                     constant, joint mode; the ready pose and 0.1 rad off on the waist and the
                     wrist, as the C++ peer). Timed, each motion: robot.move(p) (the goal checked,
                     the motion queued) and robot.waitfor(m.start), which runs the samples up to
                     the one whose setpoint is the motion's first. The rest of the motion runs
                     untimed. A block is the mean of MOVES motions; the median of the blocks is
                     reported, as Google Benchmark's median of its repetitions.
"""

import statistics
import time

import numpy as np

import rccx

ROBOT = "puma560"
MOVES = 400  # motions per timed block
CPP = "BM_MoveToFirstSetpoint"


def cpp(ctx, clock):
    """The C++ median (its name carries /iterations:N)."""
    for name, r in ctx.cpp.items():
        if name == CPP or name.startswith(CPP + "/"):
            return r[clock]
    return None


def move_first_setpoint(ctx):
    with rccx.Robot(ROBOT) as robot:
        k = robot.kinematics
        qa = k.ready
        qb = qa + np.array([0.1, 0, 0, 0, 0.1, 0])
        goals = [rccx.position("A", rccx.t6() == rccx.const("GA", k.forward(qa))),
                 rccx.position("B", rccx.t6() == rccx.const("GB", k.forward(qb)))]
        assert robot.waitfor(robot.move(goals[0]).end) == "reached"
        move, waitfor = robot.move, robot.waitfor
        state = {"next": 1}

        def block():
            wall = cpu = moving = 0
            for _ in range(MOVES):
                c0 = time.thread_time_ns()
                t0 = time.perf_counter_ns()
                m = move(goals[state["next"]])
                tm = time.perf_counter_ns()
                started = waitfor(m.start)
                t1 = time.perf_counter_ns()
                c1 = time.thread_time_ns()
                wall += t1 - t0
                cpu += c1 - c0
                moving += tm - t0
                if started != "reached" or waitfor(m.end) != "reached":
                    raise SystemExit(f"bench_move: a motion did not start or end: "
                                     f"{robot.failures()}")
                state["next"] = 1 - state["next"]
            return wall / MOVES, cpu / MOVES, moving / MOVES

        block()  # warm-up
        runs = [block() for _ in range(ctx.repetitions)]
    wall = [r[0] for r in runs]
    # Flat numbers (report.py prints another module's cases as they are): ns per motion.
    out = {"python_ns": statistics.median(wall), "python_min_ns": min(wall),
           "python_max_ns": max(wall), "cpu_python_ns": statistics.median(r[1] for r in runs),
           "python_move_call_ns": statistics.median(r[2] for r in runs),
           "repetitions": len(runs), "moves_per_block": MOVES}
    for clock in ("", "cpu_"):
        c = cpp(ctx, "cpu_ns" if clock else "real_ns")
        py = out[f"{clock}python_ns"]
        out[f"{clock}cpp_ns"] = c
        out[f"{clock}ratio"] = None if c is None else py / c
        out[f"{clock}overhead_ns"] = None if c is None else py - c
    return out


# The goal (docs/PYTHON.md "Speed"): Python does the same C++ work (move()'s goal check, the
# samples up to the first setpoint, the session's thread handoffs: about 100 us by the wall
# clock here) plus three binding calls (move, Motion.start, waitfor: each the GIL released and
# taken back, the planning lock, a result object; waitfor's slices look for signals), a few
# microseconds each. So within a quarter of C++'s time, by the wall clock: what a program sees.
# The CPU time of the calling thread is no ratio to judge by: in C++ it mostly sleeps while the
# session's threads compute the sample, so Python's calls weigh double there.
GOAL_RATIO = 1.25


def run(ctx):
    m = move_first_setpoint(ctx)
    us = lambda v: None if v is None else v / 1000.0  # noqa: E731
    return {
        "cases": {"move_first_setpoint": m},
        "goals": [
            {"text": "a move() to its first setpoint from Python against C++ "
                     "(BM_MoveToFirstSetpoint), PUMA 560 in simulated time",
             "value": m["ratio"], "value_cpu": m["cpu_ratio"], "unit": "x", "op": "<=",
             "goal": GOAL_RATIO},
        ],
        "notes": [
            {"text": "a move() to its first setpoint: Python's time over C++'s",
             "value": us(m["overhead_ns"]), "value_cpu": us(m["cpu_overhead_ns"]), "unit": "us"},
        ],
    }
