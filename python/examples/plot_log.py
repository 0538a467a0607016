#!/usr/bin/env python3
"""Loads a run log (a CSV written with RCCX_LOG=FILE or --log FILE) and saves `rccx plot`'s
four panels as PNG files with Matplotlib, one a panel and one of all four, beside it or in OUT.

    RCCX_LOG=washer.csv build/release/examples/04_washer
    PYTHONPATH=build/release/python python3 python/examples/plot_log.py washer.csv [OUT]
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no window

import rccx  # noqa: E402


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    path = pathlib.Path(argv[1])
    out = pathlib.Path(argv[2]) if len(argv) == 3 else path.parent
    try:
        log = rccx.log.load(path)
    except (FileNotFoundError, rccx.RunLogError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    errors_mm = log.path_errors_m() * 1e3
    print(f"{path}: robot {log.robot_name}, {len(log)} samples, "
          f"{log.samples['t_s'][-1] - log.samples['t_s'][0]:.2f} s, "
          f"worst path error {errors_mm.max():.3f} mm")
    names = ["joints", "path", "speed", "path_error"]
    for name, fig in zip(names, rccx.plot.figures(log)):
        fig.savefig(out / f"{path.stem}_{name}.png", dpi=100)
        print(out / f"{path.stem}_{name}.png")
    rccx.plot.figure(log).savefig(out / f"{path.stem}.png", dpi=100)
    print(out / f"{path.stem}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
