"""python/examples/kinematics.py against examples/01_kinematics on the same poses: the Microbo's
corners and the PUMA's configurations print the same joint values (to the C++'s 0.1 deg / mm)
and the same joints out of limits;
its own checks (FK(IK(T)), the Jacobian against differences, the batch against single calls)
pass and can fail."""

import re

from _examples_support import check_help, cpp_example, run_cpp, run_python
from _support import import_rccx

rccx = import_rccx()


def config_lines(out):
    """{configuration: its line} of the PUMA's section: joint values, or the joint that keeps it
    out of limits."""
    section = out.split("every configuration", 1)[1].split("2 m away", 1)[0]
    found = {}
    for line in section.splitlines():
        m = re.match(r"^  ([lr][ud][nf]):(.*)$", line)
        if m:
            found[m.group(1)] = m.group(2)
    return found


def test_same_joint_values_as_cpp():
    c = run_cpp(cpp_example("RCCX_EX_KINEMATICS"))
    assert c.returncode == 0, c.stderr
    p = run_python("kinematics", "--batch", 2000)
    assert p.returncode == 0, p.stdout + p.stderr
    # The Microbo's four corners: the same lines, configuration and joints.
    corners_c = [x for x in c.stdout.splitlines() if x.startswith("  p=(")]
    corners_p = [x for x in p.stdout.splitlines() if x.startswith("  p=(")]
    assert len(corners_c) == 4 and corners_p == corners_c
    # The PUMA's eight configurations: the reachable ones with the same joints, the others
    # kept out by the same joint (from a limit-free copy of the robot file).
    conf_c, conf_p = config_lines(c.stdout), config_lines(p.stdout)
    assert len(conf_c) == 8 and conf_p == conf_c
    reachable = sorted(n for n, line in conf_c.items() if "needs" not in line)
    assert 0 < len(reachable) < 8
    assert len(reachable) >= 2
    m = re.search(r"inverse_all: (\d+) within limits: (.*)", p.stdout)
    assert m and int(m.group(1)) == len(reachable) and sorted(m.group(2).split()) == reachable
    assert "2 m away: puma560: out of reach" in p.stdout and "2 m away: out of reach" in c.stdout
    assert "equal to the single calls: True" in p.stdout


def test_checks_can_fail(monkeypatch):
    """The example's own check fails when forward kinematics is off (here: perturbed)."""
    import importlib.util  # noqa: PLC0415
    import pathlib  # noqa: PLC0415

    path = pathlib.Path(__file__).resolve().parents[1] / "examples" / "kinematics.py"
    spec = importlib.util.spec_from_file_location("kinematics_example", path)
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    assert ex.main(["--batch", "10"]) == 0
    real = rccx.kin.robot

    class Off:
        def __init__(self, k):
            self.k = k

        def __getattr__(self, name):
            return getattr(self.k, name)

        def forward(self, q):
            T = self.k.forward(q).copy()
            T[..., 0, 3] += 1e-6  # 1 um off
            return T

    monkeypatch.setattr(rccx.kin, "robot", lambda name: Off(real(name)))
    assert ex.main(["--batch", "10"]) == 1


def test_help():
    check_help("kinematics")
