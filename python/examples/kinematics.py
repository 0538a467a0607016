"""Kinematics of the thesis's robots from Python, with no hardware (examples/01_kinematics.cpp).

What it teaches: rccx.kin's forward, inverse (closest to the ready pose, or of a named
configuration), every configuration at once (inverse_all), the Jacobian, and the vectorised
calls that take (N, dof) joint arrays in one call.

1. The Microbo's closed-form inverse puts the tool down at the four corners of the washer
   program (thesis 4.5.4.6); forward kinematics checks each answer (the same lines as the C++).
2. The PUMA 560 reaches one pose in each of its eight configurations (the same joint values as
   the C++). For a configuration out of limits, a copy of the robot file without limits
   (rccx.kin.robot_file) tells which joint keeps it out, as the C++ does with a copy of the
   model; without the robot file (robots/puma560.json under $RCCX_ROBOTS_DIR or the source
   tree) it prints rccx's reason.
3. The Jacobian at that pose against central differences of forward kinematics.
4. A batch: forward and Jacobian over N random configurations in one call each, against the
   per-configuration calls.

Exits 1 when a check fails: FK(IK(T)) off by more than 1e-9, the Jacobian off its differences
by more than 1e-6, or the batch not equal to the single calls.
Run: PYTHONPATH=build/release/python python3 python/examples/kinematics.py [--batch 10000]
"""

import argparse
import json
import math
import os
import pathlib
import sys
import tempfile
import time

import numpy as np

import rccx


def rot_x(angle_rad):
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def joints_text(k, q):
    """As the C++ prints them: ' name=12.3deg' or ' name=45.6mm'."""
    out = ""
    for name, unit, v in zip(k.joint_names, k.joint_units, q):
        out += f" {name}={math.degrees(v):.1f}deg" if unit == "rad" else f" {name}={v * 1e3:.1f}mm"
    return out


def microbo_corners():
    """The washer's tool-down corners; the largest FK(IK(T)) - T, m."""
    k = rccx.kin.robot("microbo")
    print(f"{k.title} - the washer program's tool-down corners")
    worst = 0.0
    for z_m in (0.250, 0.300):
        for y_m in (-0.150, 0.150):
            T = np.eye(4)
            T[:3, :3] = rot_x(math.pi)  # pointing down, turned half a turn about x
            T[:3, 3] = [0.325, y_m, z_m]
            try:
                q = k.inverse(T)  # closest to the ready pose
            except rccx.UnreachableError as e:
                print(f"  ({325:.0f}, {y_m * 1e3:.0f}, {z_m * 1e3:.0f}) mm: {e}")
                continue
            error = np.abs(k.forward(q) - T).max()
            worst = max(worst, error)
            print(f"  p=({325:.0f}, {y_m * 1e3:+.0f}, {z_m * 1e3:.0f}) mm  config "
                  f"{k.configuration_of(q)}:{joints_text(k, q)}")
            print(f"      FK(IK(T)) - T = {error:.1e}")
    return worst


def unlimited(name):
    """The robot `name` without joint limits (+-720 deg), from its robot file; None when the
    file is not at hand."""
    for d in (os.environ.get("RCCX_ROBOTS_DIR"), pathlib.Path(__file__).resolve().parents[2] /
              "robots"):
        path = pathlib.Path(d or "") / f"{name}.json"
        if d and path.is_file():
            break
    else:
        return None
    # Robot files allow // comment lines; JSON does not.
    text = "\n".join(x for x in path.read_text().splitlines() if not x.lstrip().startswith("//"))
    model = json.loads(text)
    for j in model["joints"]:
        j["lower_deg"], j["upper_deg"] = -720.0, 720.0
    with tempfile.TemporaryDirectory() as tmp:
        free = pathlib.Path(tmp) / f"{name}.json"
        free.write_text(json.dumps(model))
        return rccx.kin.robot_file(free)


def puma_configurations():
    """One pose in each configuration; the largest FK(IK(T)) - T, m, and the pose's joints."""
    k = rccx.kin.robot("puma560")
    q0 = np.array([-0.8, 0.7, -2.6, 0.4, 0.9, -0.5])
    T = k.forward(q0)
    print(f"\n{k.title} - one pose, every configuration (from q = {joints_text(k, q0)}")
    free = unlimited("puma560")
    worst = 0.0
    for name in k.configuration_names:
        try:
            q = k.inverse(T, configuration=name)
        except rccx.UnreachableError as e:
            try:
                q_free = free.inverse(T, configuration=name) if free else None
            except rccx.UnreachableError:
                q_free = None
            outside = ([] if q_free is None else
                       np.flatnonzero((q_free < k.lower) | (q_free > k.upper)))
            if len(outside) == 0:
                print(f"  {name}: {e}")
                continue
            j = outside[0]
            print(f"  {name}: needs {k.joint_names[j]} = {math.degrees(q_free[j]):.1f} deg, "
                  f"outside its limits {math.degrees(k.lower[j]):.0f} .. "
                  f"{math.degrees(k.upper[j]):.0f} deg")
            continue
        worst = max(worst, np.abs(k.forward(q) - T).max())
        print(f"  {name}:{joints_text(k, q)}")
    # inverse_all: every configuration within limits in one call, named.
    every = k.inverse_all(T)
    print(f"  inverse_all: {len(every)} within limits: {' '.join(n for n, _ in every)}")
    try:
        k.inverse(np.array([[1, 0, 0, 2.0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]))
    except rccx.UnreachableError as e:
        print(f"\n  2 m away: {e}")
    return worst, q0


def jacobian_check(q0):
    """The Jacobian at q0 against central differences of forward; the largest difference."""
    k = rccx.kin.robot("puma560")
    J = k.jacobian(q0)  # (6, 6): vx vy vz (m/s), wx wy wz (rad/s) per rad/s
    h_rad = 1e-6
    numeric = np.empty_like(J)
    for i in range(k.dof):
        dq = np.zeros(k.dof)
        dq[i] = h_rad
        Tp, Tm = k.forward(q0 + dq), k.forward(q0 - dq)
        numeric[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h_rad)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h_rad) @ k.forward(q0)[:3, :3].T  # [w]x
        numeric[3:, i] = [dR[2, 1], dR[0, 2], dR[1, 0]]
    diff = np.abs(J - numeric).max()
    print(f"\nJacobian at that pose (rows m/s, rad/s per rad/s), against central differences: "
          f"{diff:.1e}")
    with np.printoptions(precision=4, suppress=True):
        print(J)
    return diff


def batch(n):
    """Forward and Jacobian over n configurations in one call each; True when equal to the
    single calls."""
    k = rccx.kin.robot("puma560")
    rng = np.random.default_rng(1986)
    Q = rng.uniform(k.lower, k.upper, (n, k.dof))  # rad
    t0 = time.perf_counter()
    Ts = k.forward(Q)  # (n, 4, 4)
    t1 = time.perf_counter()
    Js = k.jacobian(Q)  # (n, 6, 6)
    t2 = time.perf_counter()
    same = all(np.array_equal(Ts[i], k.forward(Q[i])) and np.array_equal(Js[i], k.jacobian(Q[i]))
               for i in range(0, n, max(1, n // 1000)))
    reach_m = np.linalg.norm(Ts[:, :3, 3], axis=1)
    print(f"\nbatch of {n}: forward {(t1 - t0) * 1e9 / n:.0f} ns a pose, Jacobian "
          f"{(t2 - t1) * 1e9 / n:.0f} ns a pose; wrist centre {reach_m.min() * 1e3:.0f} .. "
          f"{reach_m.max() * 1e3:.0f} mm from the shoulder; equal to the single calls: {same}")
    return same


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--batch", type=int, default=10_000, metavar="N",
                    help="configurations in the vectorised forward and Jacobian (default 10000)")
    args = ap.parse_args(argv)
    if args.batch < 1:
        ap.error("--batch must be at least 1")

    fk_microbo_m = microbo_corners()
    fk_puma_m, q0 = puma_configurations()
    jac = jacobian_check(q0)
    same = batch(args.batch)
    good = fk_microbo_m < 1e-9 and fk_puma_m < 1e-9 and jac < 1e-6 and same
    if not good:
        print("FAILED: FK(IK(T)), the Jacobian or the batch is off", file=sys.stderr)
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main())
