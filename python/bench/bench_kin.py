"""rccx.kin from Python against the same work in C++ and in PyKDL (run by run.py).

fk_one    one Kinematics.forward(q) on a (6,) array, PUMA 560, q cycling through 1,024 draws
          within limits (as bench/kinematics_bench.cpp's BM_Puma560FK does in C++): the
          binding's overhead is the Python call's time, less the bare Python loop's, less C++'s.
fk_batch  forward over 100,000 configurations (one (100000, 6) array, one call) against a Python
          loop of PyKDL ChainFkSolverPos_recursive.JntToCart on the same configurations, the KDL
          chain built here from robots/puma560.json's DH table (as the C++ peer BM_KdlPuma560FK
          builds it); both give the same poses (checked, 1e-12). Two KDL loops: the calls with
          what a program needs around them for the same input and output (each row into a
          JntArray, each Frame into the (N, 4, 4) array), which the goal is judged on, and the
          calls alone (JntArrays built beforehand, one Frame reused, nothing read back: KDL's
          best case), reported beside it.
"""

import json
import re

import numpy as np

import rccx

ROBOT = "puma560"
POOL = 1024  # as kPoolSize in bench/kinematics_bench.cpp
ONE_CALLS = 200_000  # calls per timed block of fk_one
BATCH = 100_000
SEED = 19860101
TOLERANCE = 1e-12  # KDL against rccx, as kFkTolerance in bench/kinematics_bench.cpp


def kdl_chain(kdl, robots_dir):
    """PyKDL chain of the robot file's standard DH table (joints about z, as the C++ peer)."""
    text = (robots_dir / f"{ROBOT}.json").read_text(encoding="utf-8")
    model = json.loads(re.sub(r"^\s*//.*$", "", text, flags=re.M))  # the files carry // comments
    chain = kdl.Chain()
    for j in model["joints"]:
        assert j["type"] == "revolute", j
        frame = kdl.Frame.DH(j["a_m"], np.radians(j["alpha_deg"]), j["d_m"],
                             np.radians(j.get("theta_deg", 0.0)))
        chain.addSegment(kdl.Segment(kdl.Joint(kdl.Joint.RotZ), frame))
    return chain


def cpp(ctx, name, clock):
    r = ctx.cpp.get(name)
    return None if r is None else r[clock]


def fk_one(ctx, k):
    rng = np.random.default_rng(SEED)
    pool = [np.ascontiguousarray(rng.uniform(k.lower, k.upper)) for _ in range(POOL)]
    seq = pool * (ONE_CALLS // POOL)
    forward = k.forward

    def calls():
        for q in seq:
            forward(q)

    def loop():
        for q in seq:
            pass

    call = ctx.time_ns(calls, per=len(seq))
    bare = ctx.time_ns(loop, per=len(seq))
    out = {"python_call": call, "python_loop_alone": bare, "calls_per_block": len(seq)}
    # The call less the loop around it, less the same call in C++ (BM_Puma560FK): by the wall
    # clock, and by CPU time.
    for clock, key, cpp_key in (("", "median_ns", "real_ns"), ("cpu_", "cpu_median_ns", "cpu_ns")):
        python_ns = call[key] - bare[key]
        cpp_ns = cpp(ctx, "BM_Puma560FK", cpp_key)
        out[f"{clock}python_call_ns"] = python_ns
        out[f"{clock}cpp_ns"] = cpp_ns
        out[f"{clock}overhead_ns"] = None if cpp_ns is None else python_ns - cpp_ns
    return out


def fk_batch(ctx, k):
    import PyKDL as kdl  # noqa: PLC0415 (python3-pykdl; only this case needs it)

    rng = np.random.default_rng(SEED + 1)
    Q = rng.uniform(k.lower, k.upper, (BATCH, k.dof))
    chain = kdl_chain(kdl, ctx.source_dir / "robots")  # kept: the solver holds a reference
    solver = kdl.ChainFkSolverPos_recursive(chain)
    arrays = []
    for row in Q.tolist():
        a = kdl.JntArray(k.dof)
        for j, v in enumerate(row):
            a[j] = v
        arrays.append(a)
    frame = kdl.Frame()

    def kdl_calls():
        for a in arrays:
            solver.JntToCart(a, frame)

    def kdl_program():
        """What a program needs for the same input and output as k.forward(Q): each row into a
        JntArray, each Frame into a (N, 4, 4) array (collected as tuples, one array at the end:
        the quickest way we found with PyKDL's element access)."""
        a = kdl.JntArray(k.dof)
        f = kdl.Frame()
        rows = []
        for q in Q.tolist():
            for j, v in enumerate(q):
                a[j] = v
            if solver.JntToCart(a, f) < 0:
                raise RuntimeError("PyKDL JntToCart failed")
            M, p = f.M, f.p
            rows.append((M[0, 0], M[0, 1], M[0, 2], p[0], M[1, 0], M[1, 1], M[1, 2], p[1],
                         M[2, 0], M[2, 1], M[2, 2], p[2], 0.0, 0.0, 0.0, 1.0))
        return np.array(rows).reshape(-1, 4, 4)

    ours = k.forward(Q)
    theirs = kdl_program()
    difference = float(np.max(np.abs(ours - theirs)))
    if not difference <= TOLERANCE:
        raise SystemExit(f"bench_kin: rccx and PyKDL poses differ by {difference:g} "
                         f"> {TOLERANCE:g}")

    rccx_t = ctx.time_ns(lambda: k.forward(Q))
    kdl_calls_t = ctx.time_ns(kdl_calls, repetitions=min(ctx.repetitions, 5))
    kdl_program_t = ctx.time_ns(kdl_program, repetitions=3)
    out = {
        "configurations": BATCH,
        "rccx_one_call": rccx_t,
        "pykdl_loop_calls": kdl_calls_t,
        "pykdl_loop_with_conversions": kdl_program_t,
        "cpp_ns_per_pose": cpp(ctx, "BM_Puma560FK", "real_ns"),
        "cpp_cpu_ns_per_pose": cpp(ctx, "BM_Puma560FK", "cpu_ns"),
        "cpp_kdl_ns_per_pose": cpp(ctx, "BM_KdlPuma560FK", "real_ns"),
        "cpp_kdl_cpu_ns_per_pose": cpp(ctx, "BM_KdlPuma560FK", "cpu_ns"),
        "max_difference": difference,
    }
    for clock, key in (("", "median_ns"), ("cpu_", "cpu_median_ns")):
        out[f"{clock}ratio_with_conversions"] = kdl_program_t[key] / rccx_t[key]
        out[f"{clock}ratio_calls"] = kdl_calls_t[key] / rccx_t[key]
    return out


def run(ctx):
    k = rccx.kin.robot(ROBOT)
    one = fk_one(ctx, k)
    batch = fk_batch(ctx, k)
    us = lambda v: None if v is None else v / 1000.0  # noqa: E731
    return {
        "cases": {"fk_one": one, "fk_batch": batch},
        "goals": [
            {"text": "one forward(q) from Python: the binding's overhead over C++ (BM_Puma560FK)",
             "value": us(one["overhead_ns"]), "value_cpu": us(one["cpu_overhead_ns"]),
             "unit": "us", "op": "<=", "goal": 1.0},
            {"text": "forward over 100,000 configurations in one call against a Python loop of "
                     "PyKDL JntToCart, the same input and output ((N, 6) in, (N, 4, 4) out)",
             "value": batch["ratio_with_conversions"],
             "value_cpu": batch["cpu_ratio_with_conversions"],
             "unit": "x", "op": ">=", "goal": 50.0},
        ],
        # Beside the goals, said in the report: KDL's best case.
        "notes": [
            {"text": "forward over 100,000 in one call against the PyKDL JntToCart calls alone "
                     "(JntArrays built beforehand, nothing read back)",
             "value": batch["ratio_calls"], "value_cpu": batch["cpu_ratio_calls"], "unit": "x"},
        ],
    }
