#!/usr/bin/env python3
"""Runs every shell command of README.md's ```sh blocks as it is written, and checks each one's
exit code and a line of its output against the table below (ctest readme_commands).

The commands run in order, through bash, in a temporary directory laid out as a checkout after
`make` (a user's view): cells/, robots/, scripts/ and the Makefile link to the source tree,
build/release to the build under test (ctest's Debug build has tools/rccx and examples/ too),
and `rccx` on PATH is that build's tools/rccx. The environment has no RCCX_ variables, and CMAKE
is `true`, so that `make demo` and the like run what they run on the build that is there instead
of configuring and building another (the Makefile reads CMAKE ?= cmake).

Commands that serve until Ctrl-C (`rccx view`, `make demo-view`) run in a network namespace of
their own when one can be made (their fixed port cannot clash with another program's), until
they print the expected line; then they get SIGINT and must stop with 130. Blocks marked
<!-- install_test: NAME --> are tests/install_test.sh's (ctest install_outside), which runs them
against a temporary install. A README command missing from the table, or a table entry no longer
in the README, fails the test: the two are kept in step.

Usage: readme_commands.py BUILD_DIR SOURCE_DIR
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass


@dataclass
class Expect:
    code: int  # exit code; 130: stopped by the test's SIGINT (serve)
    regex: str  # searched for line by line in stdout and stderr together (or in `file`)
    stdin: str = ""
    serve: bool = False  # runs until Ctrl-C: SIGINT once the regex has matched
    skip: str = ""  # why it is not run here
    file: str = ""  # a command that prints nothing: the regex is searched in the file it wrote
    timeout_s: float = 120.0
    # A real-time command on a loaded machine may overrun and say so with exit 1 (the README's
    # "control was restarted" policy): accepted, and said, when this line is in its output.
    loaded: str = ""


ADDRESS = r"http://127\.0\.0\.1:\d+"
WASHER = r"^washer: \d+ segments in [\d.]+ s"
DB_PUT = ('rccx db put --robot microbo PICK --T 1,0,0,0.325,0,-1,0,0.15,0,0,-1,0.25 '
          '--note "over the table"')
# The command (without its trailing comment) -> what it must do.
TABLE = {
    "make demo": Expect(0, WASHER),
    "make demo-cell": Expect(0, r"^8 pads probed, \d+ on the moving board"),
    "make demo-view": Expect(130, ADDRESS, serve=True),
    "rccx serve --cell cells/cvarl.json --robots puma --interface lo --seconds 2":
        Expect(0, r"^rccx serve: stopped; robots halted, claims given back"),
    "rccx certs init certs --participants puma,microbo,program":
        Expect(0, r"^program: certs/program/cert\.pem"),
    # Two minutes of real time with two serve processes: ctest demo_distributed runs it (the
    # script the target calls) and checks its table.
    "make demo-distributed": Expect(0, r"^8 pads probed, \d+ on the moving board",
                                    skip="ctest demo_distributed runs scripts/demo-distributed"),
    "make test": Expect(0, "", skip="it is what runs this test (ctest)"),
    "rccx kin robots": Expect(0, r"^puma560 - Unimation PUMA 560"),
    "rccx kin fk --robot puma560 0 0.7854 -3.1416 0 0.7854 0 --json":
        Expect(0, r'^\{"robot":"puma560".*"T":\[\['),
    "rccx kin ik --robot puma560 --T 1,0,0,0.4521,0,1,0,-0.15005,0,0,1,0.4318 --all":
        Expect(0, r"^puma560 .*: \d solution\(s\) within limits"),
    "rccx kin ik --robot microbo --T 1,0,0,0.325,0,-1,0,0.15,0,0,-1,0.25 --config n":
        Expect(0, r"^ +d3 = +0\.35794\d* m"),
    "rccx kin ik --robot microbo --xyz 325mm,150mm,250mm --rpy 180deg,0,0 --config n":
        Expect(0, r"^ +d3 = +0\.35794\d* m"),
    "rccx report --seconds 2": Expect(0, r"^t +[\d.]+ s +theta1 +-?[\d.]+ deg d2 +[\d.]+ mm"),
    "rccx report --robot puma560 --realtime --period 1ms --seconds 10":
        Expect(0, r"latency", loaded=r"^report: control was restarted \d+ times? after overruns"),
    "rccx calib --uncalibrated": Expect(0, r"^ALL JOINTS calibrated after"),
    "rccx limp": Expect(0, r"^arm power off"),
    "rccx marsh --push 3:60": Expect(0, r"^zero gravity"),
    r"printf 'j 3\nv 20\nm 350\nw 2\nx\nX\nq\n' | rccx jointtest":
        Expect(0, r"^ +3 d3 +350\.\d+ mm"),
    r"printf 'out 5805 04\nstep 0.1\nin 5804\n' | rccx rcu": Expect(0, r"^[0-9A-F]{2}$"),
    "RCCX_LOG=washer.csv build/release/examples/washer_c": Expect(0, r"^velocity 110, 120"),
    "build/release/examples/c_guarded": Expect(0, r"^touched at z = [\d.]+ mm"),
    DB_PUT: Expect(0, r"PICK", file="rccx.db"),  # SQLite keeps the name as text
    "rccx db put --robot microbo PLACE --xyz 325mm,-150mm,250mm --rpy 180deg,0,0":
        Expect(0, r"PLACE", file="rccx.db"),
    "rccx db put --new-robot gantry HOME --xyz 0,0,1 --rpy 0,0,0":
        Expect(0, r"gantry", file="rccx.db"),
    "rccx db list --robot microbo": Expect(0, r"^microbo PICK: x 325\.000 .*\(over the table\)"),
    "rccx db export cell.json": Expect(0, r'"PICK"', file="cell.json"),
    "rccx teach --robot puma560 --db cell.db":
        Expect(0, r"saved PICK for puma560 in cell\.db", stdin="m 1 30\np\n2+\nq\nxd\nsave PICK\ne\n"),
    "rccx db --db cell.db show --robot puma560 PICK": Expect(0, r"PICK"),
    "rccx view --robot puma560": Expect(130, ADDRESS, serve=True),
    "rccx view --cell cells/cvarl.json": Expect(130, ADDRESS, serve=True),
    "rccx view --urdf robots/panda.urdf": Expect(130, ADDRESS, serve=True),
    "rccx view --cell cells/ur5e_panda.json": Expect(130, ADDRESS, serve=True),
    "RCCX_LOG=run.csv build/release/examples/04_washer": Expect(0, WASHER),
    "rccx view --log run.csv": Expect(130, ADDRESS, serve=True),
    "rccx plot run.csv -o run.svg": Expect(0, r"^run\.csv: robot microbo .*, \d+ samples, [\d.]+ s, worst path error [\d.]+ mm .*-> run\.svg"),
    "rccx plot run.csv -o run.png": Expect(0, r"^run\.csv: robot microbo .*, \d+ samples, [\d.]+ s, worst path error [\d.]+ mm .*-> run\.png"),
}


def readme_commands(readme):
    """The lines of the ```sh blocks not marked for install_test, in order."""
    lines, inside, marked, previous = [], False, False, ""
    for raw in open(readme, encoding="utf-8"):
        line = raw.strip()
        if line.startswith("```"):
            if inside:
                inside = False
            elif line == "```sh":
                inside, marked = True, previous.startswith("<!-- install_test:")
        elif inside and not marked and line and not line.startswith("#"):
            lines.append(line)
        if line:
            previous = line
    return lines


def key(line):
    """The command without its trailing comment (a # after a blank, outside quotes)."""
    return re.split(r"\s+#", line, maxsplit=1)[0].strip()


def make_checkout(work, build, source):
    for name in ("cells", "robots", "scripts", "Makefile"):
        os.symlink(os.path.join(source, name), os.path.join(work, name))
    os.makedirs(os.path.join(work, "build"))
    os.symlink(build, os.path.join(work, "build", "release"))
    os.makedirs(os.path.join(work, "bin"))
    os.symlink(os.path.join(build, "tools", "rccx"), os.path.join(work, "bin", "rccx"))
    env = {k: v for k, v in os.environ.items() if not k.startswith("RCCX_")}
    env["PATH"] = os.path.join(work, "bin") + os.pathsep + env["PATH"]
    env["CMAKE"] = "true"
    env.pop("MAKEFLAGS", None)
    env.pop("MFLAGS", None)
    return env


def own_network():
    """The prefix that runs a command in a network namespace with loopback up, or []."""
    unshare = ["unshare", "-n"] if os.geteuid() == 0 else ["unshare", "-rn"]
    probe = unshare + ["ip", "link", "set", "lo", "up"]
    if shutil.which("unshare") and shutil.which("ip") and subprocess.run(
            probe, capture_output=True).returncode == 0:
        return unshare + ["bash", "-c", 'ip link set lo up && exec bash -c "$0"']
    return []


def run_to_end(argv, expect, env, cwd):
    done = subprocess.run(argv, input=expect.stdin, capture_output=True, text=True, env=env,
                          cwd=cwd, timeout=expect.timeout_s)
    return done.returncode, done.stdout + done.stderr


def run_served(argv, expect, env, cwd):
    """Reads the output until the regex matches (or 60 s), then Ctrl-C to the process group."""
    proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=env, cwd=cwd,
                            start_new_session=True)
    seen, matched = [], threading.Event()

    def read():
        for line in proc.stdout:
            seen.append(line)
            if re.search(expect.regex, line):
                matched.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    matched.wait(60)
    os.killpg(proc.pid, signal.SIGINT)
    try:
        code = proc.wait(15)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        code = proc.wait()
    reader.join(5)
    return (128 - code if code < 0 else code), "".join(seen)


def check(line, expect, env, cwd, network):
    argv = ["bash", "-c", line]
    if expect.serve:
        code, out = run_served(network + [line] if network else argv, expect, env, cwd)
    else:
        code, out = run_to_end(argv, expect, env, cwd)
    problems = []
    if code == 1 and expect.loaded and re.search(expect.loaded, out, re.MULTILINE):
        print(f"note  exit 1 on this loaded machine: {re.search(expect.loaded, out, re.M)[0]}")
    elif code != expect.code:
        problems.append(f"exit code {code}, expected {expect.code}")
    text = out
    if expect.file:
        try:
            with open(os.path.join(cwd, expect.file), encoding="utf-8", errors="replace") as f:
                text = f.read()
        except OSError as e:
            problems.append(f"{expect.file}: {e.strerror}")
    if not re.search(expect.regex, text, re.MULTILINE):
        problems.append(f"no line of {expect.file or 'its output'} matches /{expect.regex}/")
    return problems, out


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: readme_commands.py BUILD_DIR SOURCE_DIR")
    build, source = (os.path.abspath(a) for a in sys.argv[1:])
    lines = readme_commands(os.path.join(source, "README.md"))
    failures = [f"README command not in the table of tests/readme_commands.py: {line}"
                for line in lines if key(line) not in TABLE]
    failures += [f"table entry no longer in README.md: {k}" for k in TABLE
                 if k not in {key(line) for line in lines}]
    network = own_network()
    with tempfile.TemporaryDirectory(prefix="rccx-readme-") as work:
        env = make_checkout(work, build, source)
        for line in lines:
            expect = TABLE.get(key(line))
            if expect is None:
                continue
            if expect.skip:
                print(f"skip  {line}\n      ({expect.skip})")
                continue
            start = time.monotonic()
            problems, out = check(line, expect, env, work, network)
            took = time.monotonic() - start
            print(f"{'FAIL' if problems else 'ok':5} {key(line)}  ({took:.1f} s)")
            if problems:
                tail = "\n".join(out.rstrip().splitlines()[-15:])
                failures.append(f"{line}\n  " + "; ".join(problems) + f"\n  output ends:\n{tail}")
    for f in failures:
        print(f"\nreadme_commands: {f}", file=sys.stderr)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
