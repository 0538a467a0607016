#!/usr/bin/env python3
"""Prints `make bench-python`'s JSON (python/bench/run.py) as Markdown: each case's times, the
ratios, and the goals marked met / not met. A report: exit 0 whatever the numbers, 1 when the
file is missing or not run.py's JSON.

Usage: report.py bench-results/python.json
"""

import json
import sys


def fail(message):
    print(f"bench-python report: {message}", file=sys.stderr)
    sys.exit(1)


def ns(v):
    if v is None:
        return "-"
    return f"{v:,.0f}" if v >= 100 else f"{v:.1f}"


def timing(t):
    return (f"{ns(t['median_ns'])} (min {ns(t['min_ns'])}, max {ns(t['max_ns'])}, "
            f"n={t['repetitions']})")


def print_kin(cases):
    one, batch = cases.get("fk_one"), cases.get("fk_batch")
    if one:
        print("### One forward(q), PUMA 560 (6,) array")
        print()
        print("| | ns per call, wall clock (median, min, max) | CPU |")
        print("|---|---:|---:|")
        print(f"| Python loop with the call | {timing(one['python_call'])} | "
              f"{ns(one['python_call']['cpu_median_ns'])} |")
        print(f"| Python loop alone | {timing(one['python_loop_alone'])} | "
              f"{ns(one['python_loop_alone']['cpu_median_ns'])} |")
        print(f"| the call from Python (difference) | {ns(one['python_call_ns'])} | "
              f"{ns(one['cpu_python_call_ns'])} |")
        print(f"| the same call in C++ (BM_Puma560FK) | {ns(one['cpp_ns'])} | "
              f"{ns(one['cpu_cpp_ns'])} |")
        print(f"| **the binding's overhead** | **{ns(one['overhead_ns'])}** | "
              f"**{ns(one['cpu_overhead_ns'])}** |")
        print()
    if batch:
        n = batch["configurations"]
        print(f"### forward over {n:,} configurations")
        print()
        print("| | ms in all | ns per pose | / rccx | CPU ns per pose | / rccx (CPU) |")
        print("|---|---:|---:|---:|---:|---:|")
        rows = [("rccx: k.forward(Q), one call", batch["rccx_one_call"]),
                ("PyKDL: a Python loop, the same input and output",
                 batch["pykdl_loop_with_conversions"]),
                ("PyKDL: the JntToCart calls alone", batch["pykdl_loop_calls"])]
        base = batch["rccx_one_call"]
        for text, t in rows:
            print(f"| {text} | {t['median_ns'] / 1e6:,.2f} | {ns(t['median_ns'] / n)} | "
                  f"{t['median_ns'] / base['median_ns']:,.1f} | {ns(t['cpu_median_ns'] / n)} | "
                  f"{t['cpu_median_ns'] / base['cpu_median_ns']:,.1f} |")
        print(f"| C++: rccx forward (BM_Puma560FK) | | {ns(batch['cpp_ns_per_pose'])} | | "
              f"{ns(batch['cpp_cpu_ns_per_pose'])} | |")
        print(f"| C++: KDL JntToCart (BM_KdlPuma560FK) | | {ns(batch['cpp_kdl_ns_per_pose'])} | | "
              f"{ns(batch['cpp_kdl_cpu_ns_per_pose'])} | |")
        print()
        print(f"Poses of rccx and PyKDL: max difference {batch['max_difference']:.1e}.")
        print()


def value(v, unit):
    return "not measured" if v is None else f"{v:,.3g} {unit}"


def main():
    if len(sys.argv) != 2:
        fail("usage: report.py FILE.json")
    try:
        with open(sys.argv[1], encoding="utf-8") as f:
            doc = json.load(f)
        benchmarks = doc["benchmarks"]
    except FileNotFoundError:
        fail(f"{sys.argv[1]}: no such file (run `make bench-python`)")
    except (OSError, ValueError, KeyError, TypeError) as e:
        fail(f"{sys.argv[1]}: not the JSON of python/bench/run.py ({e})")
    ctx = doc.get("context", {})
    print(f"## Python bindings benchmarks ({sys.argv[1]})")
    print()
    print(f"Run {ctx.get('date', '?')} on {ctx.get('host_name', '?')}, Python "
          f"{ctx.get('python', '?')}; medians of {ctx.get('repetitions', '?')} repetitions "
          "(time.perf_counter_ns); C++ from Google Benchmark in the same run.")
    print()
    for name, b in benchmarks.items():
        if name == "kin":
            print_kin(b["cases"])
            continue
        # Cases of other modules (bench_<name>.py): their numbers as they are.
        print(f"### {name}")
        print()
        for case, values in b.get("cases", {}).items():
            flat = ", ".join(f"{k}={v:,.4g}" if isinstance(v, (int, float)) else f"{k}={v}"
                             for k, v in values.items() if not isinstance(v, dict))
            print(f"- {case}: {flat}")
        print()
    goals = [g for b in benchmarks.values() for g in b.get("goals", [])]
    print("### Goals")
    print()
    print("| Goal | Measured (wall clock) | CPU time | Status |")
    print("|---|---:|---:|---|")
    met = 0
    for g in goals:
        v, c = g.get("value"), g.get("value_cpu")
        ok = v is not None and (v <= g["goal"] if g["op"] == "<=" else v >= g["goal"])
        met += ok
        print(f"| {g['text']} {g['op']} {g['goal']:g} {g['unit']} | {value(v, g['unit'])} | "
              f"{value(c, g['unit'])} | {'met' if ok else 'not met'} |")
    print()
    print(f"{met} of {len(goals)} goals met (judged by the wall clock, as measured).")
    notes = [n for b in benchmarks.values() for n in b.get("notes", [])]
    for n in notes:
        print(f"- {n['text']}: {value(n.get('value'), n['unit'])} "
              f"(CPU time: {value(n.get('value_cpu'), n['unit'])})")
    load = ctx.get("load_average")
    if load:
        print()
        print(f"Load average at the start: {', '.join(f'{v:.2f}' for v in load)} "
              f"on {ctx.get('cpp_context', {}).get('num_cpus', '?')} CPUs.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
