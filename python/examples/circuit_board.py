"""Two robots inspect a circuit board (thesis 4.5, figure 4.8) on the CVaRL cell
(cells/cvarl.json) in simulated time: examples/10_circuit_board.cpp's one-process run in Python.

What it teaches: a cell's robots on one clock (rccx.Cell), motions of one arm that start on the
other's events (cell.after), the objects a motion may touch (cell.touching), and a goal
written through another robot's moving frame (cell.tool_frame). The PUMA 260 picks the board
off the x-y stage and presents it to the Microbo; from the grasp on the board is wherever the
PUMA's tool is, so each test pad the Microbo probes is the equation

    T6 TOOL = BASE_INV(microbo) PUMA_TOOL GRASP PAD DOWN        (PUMA_TOOL = cell.tool_frame)

which the Microbo's generator evaluates every sample: its goals stay on the pads while the PUMA
moves the board (after the Microbo has touched TP3, the PUMA carries it 40 mm along y).

The constants are the C++'s, multiplied in the same order (the PUMA's goals folded into its
base frame as the C++'s cell.in_base_of does), so the program prints the C++'s table.

It measures, per pad, at every Microbo sample of the dwell: the distance between the Microbo's
measured probe tip (forward kinematics of its joints, through its base and tool) and where the
pad is at that instant (from the PUMA's joints of the same sample: base FK(q) TOOL GRASP PAD),
and prints the C++ example's table. The closest approach of the arms is not measured here (the
C++ reads it at every tick from the cell's collision world); the collision stops are counted.
Exits 1 when a motion failed, the collision check stopped the arms, or a probe missed its pad by
more than 2 mm (the pads are taken 4 mm across), as the C++ does; 2 for a bad option.
Run: PYTHONPATH=build/release/python python3 python/examples/circuit_board.py [--moving-speed 5]
"""

import argparse
import collections
import math
import os
import pathlib
import sys

import numpy as np

import rccx

# Test pads in the board frame (the top face's centre, x towards the Microbo), mm.
PADS = [("TP1", -5, -25), ("TP2", 10, -30), ("TP3", 30, -25), ("TP4", 35, 0), ("TP5", 30, 25),
        ("TP6", 10, 30), ("TP7", -5, 25), ("U1", 10, 0)]
START_MOVING_AFTER = 2  # TP3: touching it starts the PUMA's slow move
REPAIR_PAD = len(PADS) - 1  # U1: a longer dwell, the Microbo's hand closed
PAD_RADIUS_M = 0.002
DWELL_S = 0.5
REPAIR_S = 1.5
PROBE_ABOVE_M = 0.030
TRAVEL_M = 0.040  # the board's slow move along the world's y
TIMEOUT_S = 60.0


def translation(x_m, y_m, z_m):
    T = np.eye(4)
    T[:3, 3] = [x_m, y_m, z_m]
    return T


def rotation(axis, angle_rad):
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    T = np.eye(4)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    T[i, i], T[i, j], T[j, i], T[j, j] = c, -s, s, c
    return T


def rigid_inverse(T):
    """T^-1 of a rigid transform (R^T, -R^T p), as rccx's Transform::inverse."""
    inv = np.eye(4)
    inv[:3, :3] = T[:3, :3].T
    inv[:3, 3] = -(T[:3, :3].T @ T[:3, 3])
    return inv


def down_at(x_m, y_m, z_m):
    """The tool pointing down (approach -z) at a point of a frame whose z is up."""
    T = rotation("x", math.pi)
    T[:3, 3] = [x_m, y_m, z_m]
    return T


def tool_in_board():
    """board <- PUMA tool: the fingers on the middle of the board's -x edge (5 mm in), the
    approach tilted 45 deg towards +x and turned 30 deg towards +y (see the C++ example)."""
    return translation(-0.045, 0, 0) @ (rotation("z", math.radians(30)) @ rotation(
        "y", math.radians(135)))


def default_cell():
    for d in (os.environ.get("RCCX_DATA_DIR"), pathlib.Path(__file__).resolve().parents[2]):
        if d and (pathlib.Path(d) / "cells" / "cvarl.json").is_file():
            return str(pathlib.Path(d) / "cells" / "cvarl.json")
    return None


class PadResult:
    def __init__(self):
        self.touched_s = 0.0
        self.errors_m = []
        self.pads_m = []  # (t_s, pad position)
        self.hand_closed = False

    def speed_m_per_s(self):
        if len(self.pads_m) < 2 or self.pads_m[-1][0] <= self.pads_m[0][0]:
            return 0.0
        (t0, p0), (t1, p1) = self.pads_m[0], self.pads_m[-1]
        return float(np.linalg.norm(p1 - p0) / (t1 - t0))


class Watch:
    """Both arms' measured joints at the same sample: the PUMA samples every tick, the Microbo
    every fourth; the PUMA's recent readings are kept by sample time."""

    def __init__(self, cell, puma, microbo, grasp):
        self.cell, self.puma, self.microbo = cell, puma, microbo
        self.puma_base, self.microbo_base = cell.base("puma"), cell.base("microbo")
        self.puma_tool = cell.tool_transform("puma").value
        self.microbo_tool = cell.tool_transform("microbo").value
        self.pk, self.mk = puma.kinematics, microbo.kinematics
        self.grasp = grasp
        self.recent = collections.deque(maxlen=16)
        self.microbo_last_s = -1.0

    def pad_m(self, puma_q, pad):
        board = self.puma_base @ self.pk.forward(puma_q) @ self.puma_tool @ self.grasp
        return (board @ [pad[1] * 1e-3, pad[2] * 1e-3, 0.0, 1.0])[:3]

    def tip_m(self, microbo_q):
        return (self.microbo_base @ self.mk.forward(microbo_q) @ self.microbo_tool)[:3, 3]

    def measure(self, pad, seconds, r):
        until_s = self.microbo.time + seconds
        while self.microbo.time < until_s and self.microbo.controlling:
            self.cell.wait_for(self.cell.period)  # one tick
            tp = self.puma.time
            if not self.recent or self.recent[-1][0] != tp:
                self.recent.append((tp, self.puma.q))
            tm = self.microbo.time
            if tm == self.microbo_last_s:
                continue
            self.microbo_last_s = tm
            r.hand_closed = r.hand_closed or self.microbo.hand_closed  # as the RCU reports it
            same = [q for t, q in self.recent if t == tm]
            if not same:
                continue
            pad_now = self.pad_m(same[0], pad)
            r.errors_m.append(float(np.linalg.norm(self.tip_m(self.microbo.q) - pad_now)))
            r.pads_m.append((tm, pad_now))


def run(cell, args):
    puma_tool = cell.tool_transform("puma").value
    microbo_tool = cell.tool_transform("microbo").value
    board_home = cell.frame("board_home")
    presented = translation(0.060, 0, 0.140)
    presented_end = translation(0.060, TRAVEL_M, 0.140)
    tool_on_board = tool_in_board()
    grasp_value = rigid_inverse(tool_on_board)

    # Reachability, before anything moves: every goal solved within both arms' limits.
    puma_a, microbo_a = cell.robot("puma"), cell.robot("microbo")
    pk, mk = puma_a.kinematics, microbo_a.kinematics
    puma_base_inv = np.linalg.inv(cell.base("puma"))
    microbo_base_inv = np.linalg.inv(cell.base("microbo"))
    lifted = board_home @ translation(0, 0, 0.025)
    over_home = board_home @ translation(0, 0, 0.025)
    counts = {"puma": 0, "microbo": 0, "unreachable": 0}

    def check(k, t6, who, what):
        counts[who] += 1
        try:
            k.inverse(t6)
        except rccx.UnreachableError as e:
            counts["unreachable"] += 1
            print(f"{k.name} cannot reach {what}: {e}", file=sys.stderr)

    for b in (over_home, board_home, lifted, presented, presented_end):
        check(pk, puma_base_inv @ b @ tool_on_board @ np.linalg.inv(puma_tool), "puma",
              f"the board at ({b[0, 3] * 1e3:.0f}, {b[1, 3] * 1e3:.0f}, {b[2, 3] * 1e3:.0f}) mm")
    for b in (presented, presented_end):
        for name, x_mm, y_mm in PADS:
            for above_m in (0.0, PROBE_ABOVE_M):
                t6 = microbo_base_inv @ b @ down_at(x_mm * 1e-3, y_mm * 1e-3, above_m) @ \
                    np.linalg.inv(microbo_tool)
                check(mk, t6, "microbo", f"{name} {above_m * 1e3:.0f} mm above, board at y = "
                      f"{b[1, 3] * 1e3:.0f} mm")
    print(f"reach: {counts['puma']} PUMA goals (board on the stage, lifted, presented, moved) and "
          f"{counts['microbo']} Microbo goals (each pad and above it, board presented and moved): "
          f"{counts['unreachable']} unreachable")
    if counts["unreachable"]:
        return 1

    cell.start()
    puma, microbo = cell.robot("puma"), cell.robot("microbo")
    watch = Watch(cell, puma, microbo, grasp_value)

    # Equations. T6 PTOOL GRASP = BASE_INV(puma) BOARD, tool GRASP: the PUMA carries the board
    # on straight lines.
    T6 = rccx.t6()
    PTOOL = rccx.const("PTOOL", puma_tool)
    GRASP = rccx.const("GRASP", grasp_value)
    puma_base_inv = rigid_inverse(cell.base("puma"))

    def board_at(name, board):
        # The board's pose in the PUMA's base frame, one constant (as the C++'s in_base_of).
        in_puma = rccx.const(f"{name}_in_puma", puma_base_inv @ board)
        return rccx.position(name, T6 * PTOOL * GRASP == in_puma)

    p_over = board_at("OVER_BOARD", over_home)
    p_grip = board_at("ON_BOARD", board_home)
    p_lift = board_at("LIFT", lifted)
    p_present = board_at("PRESENT", presented)
    p_moved = board_at("MOVED", presented_end)

    # T6 TOOL = BASE_INV(microbo) PUMA_TOOL GRASP PAD DOWN: on the pad wherever the PUMA holds it.
    MTOOL = cell.tool_transform("microbo")
    MBASE_INV = cell.base_inv_transform("microbo")
    PUMA_TOOL = cell.tool_frame("puma")
    MGRASP = rccx.const("GRASP", grasp_value)

    def probe_at(name, x_mm, y_mm, z_m):
        at = rccx.const(name, down_at(x_mm * 1e-3, y_mm * 1e-3, z_m))
        return rccx.position(name, T6 * MTOOL == MBASE_INV * PUMA_TOOL * MGRASP * at)

    above = [probe_at(f"ABOVE_{n}", x, y, PROBE_ABOVE_M) for n, x, y in PADS]
    touch = [probe_at(f"TOUCH_{n}", x, y, 0.0) for n, x, y in PADS]
    # Where the Microbo waits, out of the PUMA's way; on the way it lifts its arm and draws it in.
    wait_q = mk.ready.copy()
    wait_q[0], wait_q[1], wait_q[2] = 0.8, 0.300, 0.200
    up_q = mk.ready.copy()
    up_q[1] = mk.upper[1] - 0.005  # not at the stop: the RCU overshoots
    drawn_q = up_q.copy()
    drawn_q[2] = wait_q[2]
    m_wait = rccx.joints("MICROBO_WAIT", wait_q)
    m_up = rccx.joints("MICROBO_UP", up_q)
    m_drawn = rccx.joints("MICROBO_DRAWN_IN", drawn_q)
    print(f"{p_present.describe()}\n{touch[0].describe()}")

    # 1. Pick and present.
    good = True

    def wait(arm, event):
        nonlocal good
        if not good:
            return
        w = arm.waitfor(event, timeout=TIMEOUT_S)
        if w != "reached":
            good = False
            print(f"{'PUMA' if arm is puma else 'Microbo'}: waiting for {event!r}: {w}",
                  file=sys.stderr)

    deg = math.radians
    puma.set_velocity(0.080, deg(45))
    microbo.set_velocity(0.080, deg(45))
    microbo.move(m_up)
    microbo.move(m_drawn)
    back_off = microbo.move(m_wait)
    grip = cell.touching(["board", "xy_stage"])  # the gripper closes on the board over the stage
    puma.set_velocity(0.030, deg(20))
    puma.move(p_over, after=[cell.after("microbo", back_off.end), grip])
    puma.set_mode("cartesian")
    puma.set_velocity(0.030, deg(30))
    descend = puma.move(p_grip, after=grip)
    wait(puma, descend.end)
    puma.set_hand(True)
    wait(puma, puma.dwell(0.5, after=grip).end)
    puma.set_velocity(0.050, deg(30))
    puma.move(p_lift, after=grip)
    present = puma.move(p_present, after=grip)
    if not good:
        for arm in (puma, microbo):
            for f in arm.failures():
                print(f"{'PUMA' if arm is puma else 'Microbo'}: {f['message']}", file=sys.stderr)
        print("the PUMA could not pick the board up; nothing is probed", file=sys.stderr)
        return 1

    # 2-4. Probe, with the board moving for some pads, and repair one.
    results = [PadResult() for _ in PADS]
    microbo.set_mode("cartesian")
    microbo.set_velocity(0.015, deg(10))  # slowly among the PUMA's hand and the board
    probe = cell.touching(["board"])  # the probe may touch the board; the arm and hand may not
    wait(puma, present.end)  # queued once the board is there (reach is checked when queued)
    first_above = microbo.move(above[0], after=[cell.after("puma", present.end), probe])
    wait(microbo, first_above.start)
    presented_s = puma.report(present)["end"] if good else 0.0

    slow = None
    for i, pad in enumerate(PADS):
        if not good:
            break
        if i > 0:
            microbo.move(above[i], after=probe)
        down = microbo.move(touch[i], after=probe)
        if i == START_MOVING_AFTER:  # once the Microbo has touched TP3, the board moves along y
            puma.set_velocity(args.moving_speed * 1e-3, deg(10))
            slow = puma.move(p_moved, after=[cell.after("microbo", down.end), grip])
        wait(microbo, down.end)
        if not good:
            break
        results[i].touched_s = microbo.report(down)["end"]
        # The dwell is time let pass: a motion to a moving goal that has ended keeps tracking it.
        if i == REPAIR_PAD:
            microbo.set_hand(True)
            watch.measure(pad, REPAIR_S, results[i])
            microbo.set_hand(False)
        else:
            watch.measure(pad, DWELL_S, results[i])
        microbo.move(above[i], after=probe)  # up
    if slow is not None:
        wait(puma, slow.end)

    # 5. Both back.
    microbo.set_mode("joint")
    away = microbo.move(m_wait)
    puma.set_velocity(0.050, deg(30))
    puma.move(p_lift, after=[cell.after("microbo", away.end), grip])  # out of its way first
    puma.set_velocity(0.030, deg(30))
    wait(puma, puma.move(p_grip, after=grip).end)
    puma.set_hand(False)
    wait(puma, puma.dwell(0.5, after=grip).end)
    puma.move(p_over, after=grip)
    puma.set_mode("joint")
    puma.set_velocity(0.080, deg(45))
    puma.move(puma.park, after=grip)
    wait(puma, puma.completed())
    end_s = puma.time

    # The table.
    print(f"\nboard presented at {presented_s:.2f} s; the PUMA moves it {TRAVEL_M * 1e3:.0f} mm "
          f"along y at {args.moving_speed:.1f} mm/s from the touch of "
          f"{PADS[START_MOVING_AFTER][0]}\n")
    print(" pad   x mm   y mm  board     touched s  dwell s  samples  error mm max / mean / end  "
          "hand")
    worst_m = 0.0
    moving_pads = 0
    rows = []
    for i, ((name, x_mm, y_mm), r) in enumerate(zip(PADS, results)):
        speed = r.speed_m_per_s()
        moving = speed > 0.0005  # faster than 0.5 mm/s (the servos' drift is far less)
        moving_pads += moving
        n = len(r.errors_m)
        mx = max(r.errors_m, default=0.0)
        mean = sum(r.errors_m) / n if n else 0.0
        end = r.errors_m[-1] if n else 0.0
        worst_m = max(worst_m, mx)
        good = good and n > 0
        board = f"{speed * 1e3:.1f} mm/s" if moving else "still"
        dwell = REPAIR_S if i == REPAIR_PAD else DWELL_S
        print(f"{name:4} {x_mm:6.1f} {y_mm:6.1f}  {board:<9} {r.touched_s:9.2f} {dwell:8.2f} "
              f"{n:8}  {mx * 1e3:8.3f} / {mean * 1e3:5.3f} / {end * 1e3:5.3f}  "
              f"{'closed' if r.hand_closed else 'open'}")
        rows.append(f"{name},{x_mm},{y_mm},{speed * 1e3:.3f},{r.touched_s:.3f},{n},"
                    f"{mx * 1e3:.4f},{mean * 1e3:.4f},{end * 1e3:.4f},{int(r.hand_closed)}")
    if args.csv:
        with open(args.csv, "w", encoding="utf-8") as f:
            f.write("pad,x_mm,y_mm,board_speed_mm_s,touched_s,samples,max_error_mm,"
                    "mean_error_mm,end_error_mm,hand_closed\n")
            f.write("".join(row + "\n" for row in rows))

    puma_failures, microbo_failures = puma.failures(), microbo.failures()
    stops = cell.collision_stops
    print(f"\n{len(PADS)} pads probed, {moving_pads} on the moving board; worst error "
          f"{worst_m * 1e3:.3f} mm (bound {PAD_RADIUS_M * 1e3:.1f} mm)\n"
          f"failures: PUMA {len(puma_failures) or 'none'}, "
          f"Microbo {len(microbo_failures) or 'none'}"
          f"; collision stops {stops}; closest approach of the arms' capsules not measured from "
          f"Python; simulated time {end_s:.1f} s")
    sys.stdout.flush()  # the table before the messages on stderr
    for who, fs in (("puma", puma_failures), ("microbo", microbo_failures)):
        for f in fs:
            print(f"{who} motion {f['id']} {f['kind']}: {f['message']}", file=sys.stderr)
    if not good or puma_failures or microbo_failures or stops > 0 or not (
            puma.controlling and microbo.controlling):
        print("the demonstration did not run through", file=sys.stderr)
        return 1
    if worst_m > PAD_RADIUS_M:
        print(f"a probe missed its pad by more than {PAD_RADIUS_M * 1e3:.1f} mm", file=sys.stderr)
        return 1
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--moving-speed", type=float, default=5.0, metavar="MM_PER_S",
                    help="speed of the board's slow move while the Microbo probes, mm/s "
                    "(1 .. 20, default 5)")
    ap.add_argument("--csv", help="also write the table to this CSV file (mm, s)")
    ap.add_argument("--cell", default=default_cell(),
                    help="the cell file (default: cells/cvarl.json under $RCCX_DATA_DIR, else the "
                    "source tree)")
    args = ap.parse_args(argv)
    if not 1.0 <= args.moving_speed <= 20.0:
        ap.error("--moving-speed must be within 1 .. 20")
    if not args.cell or not pathlib.Path(args.cell).is_file():
        ap.error(f"no cell file {args.cell or 'cells/cvarl.json'}: give --cell FILE")
    with rccx.Cell(args.cell) as cell:  # collision checks on, each robot on its own plant
        return run(cell, args)


if __name__ == "__main__":
    sys.exit(main())
