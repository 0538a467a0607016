"""The thesis's window washer (section 2.4.3) in Python: examples/04_washer.cpp's moves on the
simulated Microbo, through rccx.Robot.

Four constant transforms B, C, D, E put the tool at the corners of a 300 x 50 mm window in the
y-z plane, pointing down (rotated 180 deg about x); four equations T6 = B ... T6 = E. Park and
the first corner in joint mode, then three rounds in Cartesian mode, 5 mm/s and 10 deg/s faster
each round (twelve moves queued at once, joined by transitions), then park again.

Run: PYTHONPATH=build/release/python python3 python/examples/washer.py
With RCCX_LOG=FILE it writes the same sample log as the C++ washer (python/tests/test_arm.py).
"""

import math
import sys

import numpy as np

import rccx


def deg(d):
    return d * (math.pi / 180.0)  # as rccx's deg_to_rad


def corner(name, y_mm, z_mm):
    a = 180 * (math.pi / 180.0)
    c, s = math.cos(a), math.sin(a)
    T = np.array([[1, 0, 0, 0.325], [0, c, -s, y_mm * 1e-3], [0, s, c, z_mm * 1e-3],
                  [0, 0, 0, 1]])
    return rccx.const(name, T)


def main():
    B, C, D, E = (corner("B", 150, 300), corner("C", -150, 300), corner("D", -150, 250),
                  corner("E", 150, 250))
    T6 = rccx.t6()
    P1 = rccx.position("P1", T6 == B)
    P2 = rccx.position("P2", T6 == C)
    P3 = rccx.position("P3", T6 == D)
    P4 = rccx.position("P4", T6 == E)

    with rccx.Robot("microbo") as arm:  # the emulated RCU, 28 ms samples, simulated time
        tvel_mm, rvel_deg = 100.0, 100.0
        arm.set_velocity(tvel_mm * 1e-3, deg(rvel_deg))
        motions = [arm.move(arm.park)]
        arm.waitfor(motions[-1].end)
        motions.append(arm.move(P1))
        arm.waitfor(motions[-1].end)

        arm.set_mode("cartesian")
        for i in range(3):
            print(f"round {i + 1}: setvel {tvel_mm:g} mm/s along the path, {rvel_deg:g} deg/s "
                  "turning")
            for p in (P2, P3, P4, P1):
                motions.append(arm.move(p))
            tvel_mm += 5
            rvel_deg += 10
            arm.set_velocity(tvel_mm * 1e-3, deg(rvel_deg))
        w = arm.waitfor(arm.completed())

        arm.set_mode("joint")
        motions.append(arm.move(arm.park))
        arm.waitfor(motions[-1].end)

        print("\n seg  mode       start s   end s   path error mm (cmd / measured)")
        worst = 0.0
        for m in motions:
            r = arm.report(m)
            line = f"{r['id']:4}  {r['mode']:<9} {r['start']:7.2f} {r['end']:7.2f}"
            if r["mode"] == "cartesian" and r["straight_samples"] > 0:
                line += (f"   {r['max_commanded_path_error'] * 1e3:10.4f} / "
                         f"{r['max_measured_path_error'] * 1e3:7.3f}")
                worst = max(worst, r["max_measured_path_error"])
            print(line + ("  FAILED" if r["failed"] else ""))
        failures = arm.failures()
        for f in failures:
            print(f"motion {f['id']} {f['kind']}: {f['message']}", file=sys.stderr)
        total = arm.report(motions[-1])["end"] - arm.report(motions[0])["start"]
        print(f"\nwasher: {len(motions)} segments in {total:.2f} s, measured tool within "
              f"{worst * 1e3:.3f} mm of the straight edges")
    return 0 if w == "reached" and not failures else 1


if __name__ == "__main__":
    sys.exit(main())
