#!/usr/bin/env python3
"""`make bench-python`: the Python bindings' benchmarks against the same work in C++ (docs/PYTHON.md
"Speed"). Runs every python/bench/bench_*.py module's run(ctx) and writes one JSON document.

Usage: run.py --cpp bench-results/python-cpp.json --out bench-results/python.json

--cpp is Google Benchmark's JSON of the C++ peers, run by the same make target just before
(rccx_bench --benchmark_filter=... --benchmark_repetitions=N). Each module gets a Context (the
C++ medians by name, wall clock and CPU, the repetition count, a timer) and returns
{"cases": {name: {...}}, "goals": [{"text", "value", "value_cpu", "unit", "goal", "op"}],
"notes": [...]}; the modules share the timing rules below. A new comparison is a new
bench_<topic>.py with a run(ctx) function (a Python `move()` to its first setpoint against C++'s
belongs in bench_move.py, its C++ peer added to the Makefile's BENCH_PYTHON_CPP filter).

Timing: time.perf_counter_ns around a block of calls, several repetitions, the median reported
(and the minimum and maximum beside it); the thread's CPU time beside it, as Google Benchmark
gives real and CPU time. Goals are judged on both: on a machine shared with other work the
wall clock counts their time too.
"""

import argparse
import importlib
import json
import os
import pathlib
import platform
import statistics
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
TO_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}


def cpp_medians(path):
    """Benchmark name -> {"real_ns", "cpu_ns"}: the median times from Google Benchmark's JSON
    (the "_median" aggregate when present, else the median of the plain runs); errors left out."""
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    medians, plain = {}, {}
    for b in data.get("benchmarks", []):
        if b.get("error_occurred"):
            continue
        name = (b.get("run_name") or b["name"]).removesuffix("/real_time")
        unit = TO_NS[b.get("time_unit", "ns")]
        times = (float(b["real_time"]) * unit, float(b["cpu_time"]) * unit)
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                medians[name] = times
        else:
            plain.setdefault(name, []).append(times)
    for name, runs in plain.items():
        medians.setdefault(name, (statistics.median(r[0] for r in runs),
                                  statistics.median(r[1] for r in runs)))
    return ({name: {"real_ns": r, "cpu_ns": c} for name, (r, c) in medians.items()},
            data.get("context", {}))


class Context:
    def __init__(self, cpp, repetitions, source_dir):
        self.cpp = cpp  # C++ benchmark name -> {"real_ns", "cpu_ns"} (medians)
        self.repetitions = repetitions
        self.source_dir = source_dir  # the checkout (robots/ ...)

    def time_ns(self, block, per=1, repetitions=None):
        """block() timed `repetitions` times after one warm-up run, by the wall clock
        (time.perf_counter_ns) and by the thread's CPU time (time.thread_time_ns: what a loaded
        machine's other processes do not inflate; C++ calls made with the GIL released run on
        this thread too). {"median_ns", "min_ns", "max_ns", "cpu_median_ns", "repetitions"},
        per unit (the block's time / per)."""
        block()
        wall, cpu = [], []
        for _ in range(repetitions or self.repetitions):
            c0 = time.thread_time_ns()
            t0 = time.perf_counter_ns()
            block()
            wall.append((time.perf_counter_ns() - t0) / per)
            cpu.append((time.thread_time_ns() - c0) / per)
        return {"median_ns": statistics.median(wall), "min_ns": min(wall), "max_ns": max(wall),
                "cpu_median_ns": statistics.median(cpu), "repetitions": len(wall)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cpp", required=True, help="Google Benchmark JSON of the C++ peers")
    parser.add_argument("--out", required=True, help="the JSON document written")
    parser.add_argument("--repetitions", type=int, default=7)
    parser.add_argument("--only", help="run only bench_<ONLY>.py")
    args = parser.parse_args()

    cpp, cpp_context = cpp_medians(args.cpp)
    ctx = Context(cpp, args.repetitions, HERE.parents[1])
    sys.path.insert(0, str(HERE))
    modules = sorted(p.stem for p in HERE.glob("bench_*.py"))
    if args.only:
        modules = [m for m in modules if m == f"bench_{args.only}"]
    import rccx  # noqa: PLC0415 (after the arguments: --help works without the module)

    doc = {
        "context": {
            "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "host_name": platform.node(),
            "python": sys.version.split()[0],
            "python_executable": sys.executable,
            "rccx_module": os.path.realpath(rccx._rccx.__file__),
            "repetitions": args.repetitions,
            "load_average": os.getloadavg(),  # a loaded machine inflates wall-clock times
            "cpp_file": args.cpp,
            "cpp_context": {k: cpp_context.get(k) for k in ("date", "num_cpus", "mhz_per_cpu")},
        },
        "benchmarks": {},
    }
    for name in modules:
        print(f"bench-python: {name} ...", file=sys.stderr, flush=True)
        doc["benchmarks"][name.removeprefix("bench_")] = importlib.import_module(name).run(ctx)
    pathlib.Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
    print(f"bench-python: wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
