"""rccx.kin's forward kinematics and Jacobian of the shipped URDFs against Orocos KDL (Debian's
python3-pykdl), whose chain this test builds from the URDF's own numbers (origins, rpy, axes)
the way kdl_parser does, with no code of rccx's in between."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from _support import REQUIRED, ROBOTS_DIR, import_rccx, random_joints

rccx = import_rccx()
try:
    import PyKDL as kdl
except ImportError as e:
    if REQUIRED:
        raise
    pytest.skip(f"PyKDL is not importable ({e}): apt-get install python3-pykdl",
                allow_module_level=True)

URDFS = ["ur5e.urdf", "panda.urdf", "puma560.urdf"]


def floats(text, default):
    return [float(v) for v in (text or default).split()]


def kdl_chain(path):
    """The KDL chain from the URDF's root to its only leaf (the shipped URDFs do not branch)."""
    root = ET.parse(path).getroot()
    joints = root.findall("joint")
    child_links = {j.find("child").get("link") for j in joints}
    (base,) = [l.get("name") for l in root.findall("link") if l.get("name") not in child_links]
    chain = kdl.Chain()
    link = base
    while True:
        below = [j for j in joints if j.find("parent").get("link") == link]
        if not below:
            return chain
        assert len(below) == 1, f"{path}: {link} branches"
        (j,) = below
        origin = j.find("origin")
        xyz = floats(origin.get("xyz") if origin is not None else None, "0 0 0")
        rpy = floats(origin.get("rpy") if origin is not None else None, "0 0 0")
        F = kdl.Frame(kdl.Rotation.RPY(*rpy), kdl.Vector(*xyz))
        kind = j.get("type")
        if kind in ("revolute", "continuous", "prismatic"):
            axis_el = j.find("axis")
            axis = kdl.Vector(*floats(axis_el.get("xyz") if axis_el is not None else None, "1 0 0"))
            jt = kdl.Joint.TransAxis if kind == "prismatic" else kdl.Joint.RotAxis
            joint = kdl.Joint(j.get("name"), F.p, F.M * axis, jt)
        else:
            assert kind == "fixed", f"{path}: joint type {kind}"
            joint = kdl.Joint(j.get("name"), kdl.Joint.Fixed)
        link = j.find("child").get("link")
        chain.addSegment(kdl.Segment(link, joint, F))


def kdl_array(q):
    a = kdl.JntArray(len(q))
    for i, v in enumerate(q):
        a[i] = float(v)
    return a


@pytest.mark.parametrize("name", URDFS)
def test_forward_equals_kdls(name):
    path = ROBOTS_DIR / name
    k = rccx.kin.urdf(path)
    chain = kdl_chain(path)
    assert chain.getNrOfJoints() == k.dof
    fk = kdl.ChainFkSolverPos_recursive(chain)
    Q = random_joints(k, 100, seed=41)
    Ts = k.forward(Q)
    for q, T in zip(Q, Ts):
        F = kdl.Frame()
        assert fk.JntToCart(kdl_array(q), F) >= 0
        want = np.array([[F.M[r, c] for c in range(3)] + [F.p[r]] for r in range(3)]
                        + [[0.0, 0.0, 0.0, 1.0]])
        np.testing.assert_allclose(T, want, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", URDFS)
def test_jacobian_equals_kdls(name):
    # KDL's Jacobian: the tip's twist (its origin's velocity, then the angular velocity) in the
    # base frame, per unit joint speed: rccx's geometric Jacobian of T6.
    path = ROBOTS_DIR / name
    k = rccx.kin.urdf(path)
    chain = kdl_chain(path)  # KDL's solvers keep a reference to it: alive as long as they are
    solver = kdl.ChainJntToJacSolver(chain)
    for q in random_joints(k, 20, seed=42):
        J = kdl.Jacobian(k.dof)
        assert solver.JntToJac(kdl_array(q), J) >= 0
        want = np.array([[J[r, c] for c in range(k.dof)] for r in range(6)])
        np.testing.assert_allclose(k.jacobian(q), want, rtol=0, atol=1e-12)
