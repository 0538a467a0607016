"""Touch a table, then wipe along it holding a force: a PUMA 560 with a wrist sensor on the
MuJoCo plant, in simulated time (examples/11_touch_and_wipe.cpp in Python).

What it teaches: a robot with a force sensor (rccx.Robot(plant="mujoco", scene=...)), the
tool's weight taken out of the readings (set_tool_load), and RCCL's force steps:
  1. touch: a guarded move down (set_guard("along", "fz", 5 N): the motion ends, as nextmove
     does, once the tool presses 5 N along its z) finds the table; contact() says where the
     touch began, and update_from_contact() writes its height into the hold TABLE;
  2. wipe: compliance along the tool's z (set_compliance: hold the force there) while the
     motion runs 150 mm along x: the arm follows the table whatever its true height;
  3. leave: lock again (set_compliance()) and go up, then park.
The force it prints is the sensor's reading (arm.wrench) with the tool's weight taken out
(rccx.external_wrench) and carried to the tool tip (rccx.wrench_at_tool), as the C++ does.

Exits 1 when the touch is more than 0.5 mm off the table's true height or the mean force while
wiping is more than 10 % off the force asked, as the C++ example.
Run: PYTHONPATH=build/release/python python3 python/examples/touch_and_wipe.py [--table-mm Z]
     [--force N]
"""

import argparse
import math
import sys

import numpy as np

import rccx

TOOL_LENGTH_M = 0.10
TOOL_RADIUS_M = 0.008
TOOL_MASS_KG = 0.4
TOOL_COM_M = [0.0, 0.0, TOOL_LENGTH_M / 2]


def translation(x_m, y_m, z_m):
    T = np.eye(4)
    T[:3, 3] = [x_m, y_m, z_m]
    return T


def scene(table_mm):
    """The MuJoCo plant's table and tool, in a robot file's "hardware": {"mujoco": ...} keys."""
    return {
        "boxes": [{"name": "table", "center_m": [0.45, 0.0, table_mm * 1e-3 - 0.02],
                   "half_size_m": [0.40, 0.40, 0.02], "friction": 0.2}],
        # A tool with some give (a 20 ms contact, not steel on steel) and modest friction: what
        # force control through position servos sampled at 10 ms wants (docs/FORCE.md).
        "contact_time_constant_s": 0.02,
        "tool": {"mass_kg": TOOL_MASS_KG, "com_m": TOOL_COM_M, "length_m": TOOL_LENGTH_M,
                 "radius_m": TOOL_RADIUS_M, "friction": 0.2},
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--table-mm", type=float, default=-203.0,
                    help="where the table's top really is, mm below the shoulder (the program "
                    "believes -200 and finds out); -300 .. -150, default -203")
    ap.add_argument("--force", type=float, default=5.0, dest="force_N",
                    help="the force to hold while wiping, N; 1 .. 40, default 5")
    args = ap.parse_args(argv)
    if not -300.0 <= args.table_mm <= -150.0:
        ap.error("--table-mm must be within -300 .. -150")
    if not 1.0 <= args.force_N <= 40.0:
        ap.error("--force must be within 1 .. 40")

    with rccx.Robot("puma560", plant="mujoco", scene=scene(args.table_mm)) as arm:
        arm.set_tool_load(TOOL_MASS_KG, TOOL_COM_M)
        k = arm.kinematics

        # T6 TOOL = TABLE SPOT: SPOT a point above, on or along the table, the tool pointing down.
        TOOL = rccx.const("TOOL", translation(0, 0, TOOL_LENGTH_M))
        TABLE = rccx.hold("TABLE", translation(0, 0, -0.200))
        T6 = rccx.t6()

        def spot(name, x_mm, y_mm, z_mm):
            S = translation(x_mm * 1e-3, y_mm * 1e-3, z_mm * 1e-3)
            c, s = math.cos(math.pi), math.sin(math.pi)  # Rot(x, 180 deg): pointing down
            S[:3, :3] = [[1, 0, 0], [0, c, -s], [0, s, c]]
            return rccx.position(name, T6 * TOOL == TABLE * rccx.const(name, S))

        def wait(m):
            w = arm.waitfor(m.end)
            if w != "reached":
                print(f"waitfor: {w}", file=sys.stderr)
                for f in arm.failures():
                    print(f"  {f['message']}", file=sys.stderr)
                sys.exit(1)

        above = spot("ABOVE", 400, 100, 30)
        into = spot("INTO", 400, 100, -30)  # 30 mm below where the table is believed

        # 1. Touch.
        wait(arm.move(above))
        arm.set_mode("cartesian")
        arm.set_velocity(0.005, math.radians(30))  # a search: slowly (docs/FORCE.md)
        arm.set_guard("along", "fz", 5.0)  # N along the tool's z
        down = arm.move(into)
        wait(down)
        arm.set_guard(None)
        touch = arm.contact(down)
        if touch is None:
            print("no contact: the table is not where the program looked", file=sys.stderr)
            return 1
        touched_z_mm = touch["tool_frame"][2, 3] * 1e3
        arm.update_from_contact(down, TABLE, spot("ON", 400, 100, 0))
        print(f"touched at z = {touched_z_mm:.2f} mm (the table's top is at {args.table_mm:.2f} "
              "mm): TABLE updated")

        # 2. Wipe 150 mm along x, pressing.
        force = np.zeros(6)
        force[2] = args.force_N
        arm.set_compliance(["fz"], force=force)
        arm.set_velocity(0.020, math.radians(30))
        wipe = arm.move(spot("ALONG", 550, 100, 0))
        pressed_N = []
        t0_s = arm.time
        while not arm.happened(wipe.end):
            arm.wait_for(0.010)
            t6 = k.forward(arm.q)
            contact = rccx.external_wrench(arm.wrench, t6, TOOL_MASS_KG, TOOL_COM_M)
            f_N = -rccx.wrench_at_tool(TOOL.value, contact)[2]  # what the tool presses
            if arm.time - t0_s > 1.0:  # after the first second: steady
                pressed_N.append(f_N)
        wait(wipe)
        mean_N = float(np.mean(pressed_N)) if pressed_N else 0.0
        lo_N = min(pressed_N, default=0.0)
        hi_N = max(pressed_N, default=0.0)
        print(f"wiped 150 mm holding {args.force_N:.1f} N: measured {mean_N:.2f} N on average, "
              f"{lo_N:.2f} .. {hi_N:.2f} N")

        # 3. Leave.
        arm.set_compliance()
        wait(arm.move(spot("UP", 550, 100, 50)))
        arm.set_mode("joint")
        wait(arm.move(arm.park))

    good = (abs(touched_z_mm - args.table_mm) < 0.5 and len(pressed_N) > 0
            and abs(mean_N - args.force_N) < 0.1 * args.force_N)
    print("done" if good else "FAILED: the touch or the force was off")
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main())
