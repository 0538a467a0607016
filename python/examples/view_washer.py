"""The window washer (washer.py, examples/04_washer) in real time, watched in the browser:
rccx.view.serve shows the Microbo wiping the window's edges and the four corners it goes to.

Run: PYTHONPATH=build/release/python python3 python/examples/view_washer.py [--port 8080]
     [--rounds 3] [--wait 0]
then open the address it prints (--port 0: any free port). --wait: seconds to wait before the
first move (time to open the page); after the last move the page stays until Enter (or
--linger seconds).
"""

import argparse
import sys
import time

import rccx
from washer import corner, deg


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--port", type=int, default=8080)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--wait", type=float, default=0.0)
    parser.add_argument("--linger", type=float, help="seconds the page stays after the moves "
                        "(default: until Enter)")
    args = parser.parse_args()

    T6 = rccx.t6()
    corners = [rccx.position(f"P{i + 1}", T6 == corner(n, y, z))
               for i, (n, y, z) in enumerate((("B", 150, 300), ("C", -150, 300),
                                               ("D", -150, 250), ("E", 150, 250)))]
    with rccx.Robot("microbo", clock="real_time") as arm, \
            rccx.view.serve(arm, port=args.port) as view:  # says "rccx view: open URL"
        time.sleep(args.wait)
        arm.set_velocity(0.1, deg(100))
        arm.waitfor(arm.move(arm.park).end)
        arm.waitfor(arm.move(corners[0]).end)
        arm.set_mode("cartesian")
        for i in range(args.rounds):
            print(f"round {i + 1}", flush=True)
            for p in corners[1:] + corners[:1]:
                arm.move(p)
            arm.set_velocity(0.1 + 0.005 * (i + 1), deg(100 + 10 * (i + 1)))
        done = arm.waitfor(arm.completed())
        arm.set_mode("joint")
        arm.waitfor(arm.move(arm.park).end)
        print(f"washer: {done}; the page stays at {view.url}", flush=True)
        if args.linger is not None:
            time.sleep(args.linger)
        else:
            input("Enter to stop ")
    return 0 if done == "reached" else 1


if __name__ == "__main__":
    sys.exit(main())
