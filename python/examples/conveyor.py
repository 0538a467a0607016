"""A conveyor tracked through a stream transform on the simulated PUMA 560
(examples/05_conveyor.cpp in Python).

What it teaches: a moving goal fed from Python. An object rides a belt along y at 40 mm/s;
where the wrist must be is the equation

    T6 = CONV OBJ GRASP

In the C++ example CONV is a functional transform, a C++ function of the setpoint's time that
the trajectory generator calls every sample. Python never runs in the sample loop, so here CONV
is an rccx.stream: the program put()s the belt's pose and the generator reads the newest one
at every sample (lock-free). How it is fed:
  --clock simulated (default): time runs only while the program waits, so the program steps
      the robot one sample at a time (arm.wait_for(period)) and puts the belt's pose for the
      coming setpoint before each step: deterministic, as a conveyor encoder read each sample;
  --clock real_time: a Python thread reads the clock and puts the pose every --feed-ms, as a
      thread reading a conveyor's encoder would; the goal is then as old as the last put.
Each put() says the time the pose is for and the belt's velocity (put(T, at=, velocity=)), so
the generator moves the pose on to each setpoint's own time: fed sample by sample, the stream
gives what the C++ function does, and the program prints the C++'s figures; fed less often
(--put-every) or by a thread that the machine's load holds up, the goal still moves smoothly.
With --no-velocity the poses are put bare: the goal stands still between puts and then jumps,
which the generator's acceleration guard refuses once the jump is large (the motion fails).

The arm goes above the belt in joint mode, moves in Cartesian mode onto the moving object,
rides along for 3 s, then parks. It prints the tracking lag: at every sample of those 3 s, the
distance between the measured wrist centre (forward kinematics of arm.q) and the object at the
same instant, max and mean in mm. Exits 1 when a motion fails or the lag passes --bound-mm.
Run: PYTHONPATH=build/release/python python3 python/examples/conveyor.py [--clock real_time]
"""

import argparse
import math
import sys
import threading
import time

import numpy as np

import rccx

BELT_SPEED_M_PER_S = 0.040
OBJ_AT_0_M = np.array([0.450, -0.250, -0.250])
RIDE_S = 3.0


def translation(x_m, y_m, z_m):
    T = np.eye(4)
    T[:3, 3] = [x_m, y_m, z_m]
    return T


def belt(t_s):
    """The belt's travel at t_s (s on the session's clock): the conveyor frame, m."""
    return translation(0.0, BELT_SPEED_M_PER_S * t_s, 0.0)


BELT_VELOCITY = np.array([0.0, BELT_SPEED_M_PER_S, 0.0, 0.0, 0.0, 0.0])  # m/s, rad/s


def put_belt(conv, t_s, with_velocity):
    """Puts the belt's pose at session time t_s, with that time and its velocity (the stream
    extrapolates it to each setpoint's time) or bare."""
    if with_velocity:
        conv.put(belt(t_s), at=t_s, velocity=BELT_VELOCITY)
    else:
        conv.put(belt(t_s))


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


class SteppedFeed:
    """Simulated time: the program runs the samples one by one, putting the belt's pose for the
    setpoint each computes (`lead_s` ahead of the last sample read) every `every` samples."""

    def __init__(self, arm, conv, lead_s, every, with_velocity):
        self.arm, self.conv, self.lead_s = arm, conv, lead_s
        self.every, self.with_velocity, self.steps = every, with_velocity, 0

    def step(self):
        if self.steps % self.every == 0:
            put_belt(self.conv, self.arm.time + self.lead_s, self.with_velocity)
        self.steps += 1
        return self.arm.wait_for(self.arm.period)

    def waitfor(self, event, timeout_s=60.0):
        t_end = self.arm.time + timeout_s
        while not self.arm.happened(event) and self.arm.time < t_end:
            if self.step() is not None:
                return "session_ended"
        return self.arm.waitfor(event, timeout=0.0)

    def close(self):
        pass


class ThreadFeed:
    """Real time: a Python thread puts the belt's pose every `feed_s`, from the host's clock
    mapped onto the session's; the program waits as usual."""

    def __init__(self, arm, conv, lead_s, feed_s, with_velocity):
        self.arm = arm
        self.offset_s = arm.time - time.monotonic()  # session time - host time, about
        self.stop = threading.Event()

        def put():
            put_belt(conv, time.monotonic() + self.offset_s + lead_s, with_velocity)

        def run():
            while not self.stop.is_set():
                put()
                self.stop.wait(feed_s)

        put()
        self.thread = threading.Thread(target=run, name="conveyor-feed", daemon=True)
        self.thread.start()

    def step(self):
        return self.arm.wait_for(self.arm.period)

    def waitfor(self, event, timeout_s=60.0):
        return self.arm.waitfor(event, timeout=timeout_s)

    def close(self):
        self.stop.set()
        self.thread.join()


def feeding(args):
    how = ("by a thread" if args.clock == "real_time" else
           "sample by sample" if args.put_every == 1 else f"every {args.put_every} samples")
    return how + (", bare poses" if args.no_velocity else ", poses with their time and velocity")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--clock", choices=("simulated", "real_time"), default="simulated",
                    help="simulated (default: the program steps the samples and feeds the belt "
                    "before each) or real_time (a thread feeds it)")
    ap.add_argument("--feed-ms", type=float, default=5.0,
                    help="real_time: the feeding thread's period, ms (default 5)")
    ap.add_argument("--put-every", type=int, default=1, metavar="N",
                    help="simulated: put the belt's pose every N samples (default 1)")
    ap.add_argument("--no-velocity", action="store_true",
                    help="put bare poses, without their time and velocity: the goal stands "
                    "between puts and jumps at each")
    ap.add_argument("--bound-mm", type=float, default=None,
                    help="the largest tracking lag accepted, mm (default: 2, the C++ example's, "
                    "plus the belt's travel in two feed periods for bare poses in real time)")
    args = ap.parse_args(argv)
    if not 0.5 <= args.feed_ms <= 100.0:
        ap.error("--feed-ms must be within 0.5 .. 100")
    if not 1 <= args.put_every <= 100:
        ap.error("--put-every must be within 1 .. 100")
    # Bare poses fed by a thread are up to a feed period old: the belt's travel in two more.
    bound_m = (args.bound_mm * 1e-3 if args.bound_mm is not None else
               0.002 + (2 * BELT_SPEED_M_PER_S * args.feed_ms * 1e-3
                        if args.clock == "real_time" and args.no_velocity else 0.0))

    T6 = rccx.t6()
    CONV = rccx.stream("CONV", belt(0.0))
    OBJ = rccx.const("OBJ", translation(*OBJ_AT_0_M))
    pointing = rot_y(math.radians(-45)) @ rot_x(math.radians(180))
    grasp = np.eye(4)
    grasp[:3, :3] = pointing
    GRASP = rccx.const("GRASP", grasp)
    ON_BELT = rccx.position("ON_BELT", T6 == CONV * OBJ * GRASP)
    # A fixed point 100 mm above the belt to start from: T6 = OVER GRASP.
    OVER = rccx.const("OVER", translation(0.450, -0.050, -0.150))
    ABOVE_BELT = rccx.position("ABOVE_BELT", T6 == OVER * GRASP)
    print(f"{ON_BELT.describe()}: belt at {BELT_SPEED_M_PER_S * 1e3:.0f} mm/s along y "
          f"(a stream fed {feeding(args)})")

    with rccx.Robot("puma560", clock=args.clock) as arm:  # PID servos, 10 ms samples
        period_s = arm.period
        # The next sample comes one period after the last one read (arm.time), and the setpoint
        # it computes is for two periods after it (the session's pipeline): put the belt there.
        lead_s = 3 * period_s
        with_velocity = not args.no_velocity
        feed = (SteppedFeed(arm, CONV, lead_s, args.put_every, with_velocity)
                if args.clock == "simulated" else
                ThreadFeed(arm, CONV, lead_s, args.feed_ms * 1e-3, with_velocity))
        k = arm.kinematics
        try:
            motions = [arm.move(ABOVE_BELT)]  # joint mode
            w = feed.waitfor(motions[-1].end)
            arm.set_mode("cartesian")
            arm.set_velocity(0.100, math.radians(100))  # 2.5 times the belt's speed
            motions.append(arm.move(ON_BELT))
            if w == "reached":
                w = feed.waitfor(motions[-1].end)
            caught_s = arm.time

            # The motion has ended; the generator keeps the wrist on the object.
            lags_m, times_s, along_m, ys_m = [], [], [], []
            last_s = -1.0
            while w == "reached" and arm.time < caught_s + RIDE_S:
                if feed.step() is not None:
                    break
                t_s = arm.time
                if t_s == last_s:  # real time: no new sample yet
                    continue
                last_s = t_s
                wrist = k.forward(arm.q)[:3, 3]  # measured
                obj = OBJ_AT_0_M + [0.0, BELT_SPEED_M_PER_S * t_s, 0.0]  # where it is then
                lags_m.append(np.linalg.norm(wrist - obj))
                times_s.append(t_s)
                along_m.append(abs(obj[1] - wrist[1]))
                ys_m.append(obj[1])

            arm.set_mode("joint")
            motions.append(arm.move(arm.park))
            if w == "reached":
                w = feed.waitfor(motions[-1].end)
        finally:
            feed.close()

        print("\n seg  mode       start s   end s   T s   to")
        names = ["ABOVE_BELT", "ON_BELT (the moving object)", "park"]
        for m, name in zip(motions, names):
            r = arm.report(m)
            print(f"{r['id']:4}  {r['mode']:<9} {r['start']:7.2f} {r['end']:7.2f} "
                  f"{r['duration']:5.2f}   {name}{'  FAILED' if r['failed'] else ''}")
        failures = arm.failures()

    lags_m = np.array(lags_m)
    n = len(lags_m)
    if n:
        i = int(np.argmax(lags_m))
        times = np.array(times_s)
        settled = lags_m[times >= caught_s + 0.5]
        print(f"\ntracking for {times[-1] - times[0] + period_s:.2f} s ({n} samples) from "
              f"t = {caught_s:.2f} s, the object from y = {ys_m[0] * 1e3:.0f} mm to "
              f"{ys_m[-1] * 1e3:.0f} mm")
        print(f"  measured wrist centre to the object: max {lags_m[i] * 1e3:.3f} mm (at t = "
              f"{times[i]:.2f} s), mean {lags_m.mean() * 1e3:.3f} mm")
        print(f"  along the belt at most {max(along_m) * 1e3:.3f} mm; 0.5 s after the catch and "
              f"on: at most {settled.max() * 1e3 if len(settled) else 0.0:.3f} mm")
    for f in failures:
        print(f"motion {f['id']} {f['kind']}: {f['message']}", file=sys.stderr)
    if w != "reached" or failures:
        print(f"waitfor: {w}", file=sys.stderr)
        return 1
    # Simulated: one sample a step; real time: the samples seen (about one a period).
    wanted = 250 if args.clock == "simulated" else 150
    if n < wanted or lags_m.max() > bound_m:
        print(f"tracking: {n} samples, lag {lags_m.max() * 1e3 if n else 0:.3f} mm (expected "
              f">= {wanted} and <= {bound_m * 1e3:.1f} mm)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
