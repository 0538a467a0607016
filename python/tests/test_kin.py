"""rccx.kin against the C++ library on the same input: the rccx command's `kin fk`, `kin ik`
and `kin robots` (--json, float64 printed to round-trip) are the independent C++ path; the
vectorised calls against the per-call ones."""

import json

import numpy as np
import pytest

from _support import ROBOTS_DIR, cli, cli_json, import_rccx, numbers, random_joints

rccx = import_rccx()

BUILTIN = ["microbo", "panda", "puma260", "puma560", "stanford", "ur5e"]
URDFS = ["ur5e.urdf", "panda.urdf", "puma560.urdf"]


def robot_args(which):
    """(the Python object, the rccx command's robot options) for a shipped name or a URDF."""
    if which.endswith(".urdf"):
        path = ROBOTS_DIR / which
        return rccx.kin.urdf(path), ["--urdf", path]
    return rccx.kin.robot(which), ["--robot", which]


def test_the_shipped_robots_are_the_commands():
    assert rccx.kin.robot_names() == [r["name"] for r in cli_json("kin", "robots", "--json")]
    assert set(BUILTIN) <= set(rccx.kin.robot_names())


@pytest.mark.parametrize("name", BUILTIN)
def test_limits_and_names_are_the_commands(name):
    k = rccx.kin.robot(name)
    (entry,) = [r for r in cli_json("kin", "robots", "--json") if r["name"] == name]
    joints = entry["joints"]
    assert k.name == name and k.title == entry["title"] and k.solver == entry["solver"]
    assert k.dof == len(joints)
    assert k.joint_names == [j["name"] for j in joints]
    assert k.joint_units == [j["unit"] for j in joints]
    np.testing.assert_array_equal(k.lower, [j["lower"] for j in joints])
    np.testing.assert_array_equal(k.upper, [j["upper"] for j in joints])
    assert np.all(k.lower <= k.ready) and np.all(k.ready <= k.upper)


@pytest.mark.parametrize("which", BUILTIN + URDFS)
def test_forward_equals_the_commands(which):
    k, args = robot_args(which)
    for q in random_joints(k, 4, seed=27):
        out = cli_json("kin", "fk", *args, "--json", "--", *map(repr, q.tolist()))
        np.testing.assert_allclose(out["q"], q, rtol=0, atol=0)
        T = k.forward(q)
        assert T.shape == (4, 4) and T.dtype == np.float64
        # The same C++ call on the same float64s: equal to the last bit.
        np.testing.assert_array_equal(T, np.array(out["T"]))


@pytest.mark.parametrize("which", BUILTIN + URDFS)
def test_inverse_and_inverse_all_equal_the_commands(which):
    k, args = robot_args(which)
    for q in random_joints(k, 3, seed=28):
        T = k.forward(q)
        pose = ["--T", numbers(T[:3].ravel())]
        # Near the drawn pose: the numeric solvers start there; closed forms pick by it.
        near = ["--near", numbers(q)]
        out = cli_json("kin", "ik", *args, *pose, *near, "--json")
        got = k.inverse(T, near=q)
        np.testing.assert_array_equal(got, out["q"])
        np.testing.assert_allclose(k.forward(got), T, atol=1e-9)

        out_all = cli_json("kin", "ik", *args, *pose, *near, "--all", "--json")
        got_all = k.inverse_all(T, near=q)
        assert len(got_all) == len(out_all["solutions"])
        for (name, qa), s in zip(got_all, out_all["solutions"]):
            assert name == (s["config"] if k.configuration_names else None)
            np.testing.assert_array_equal(qa, s["q"])
            np.testing.assert_allclose(k.forward(qa), T, atol=1e-9)

        for name in k.configuration_names:
            code, out, err = cli("kin", "ik", *args, *pose, "--config", name, "--json")
            if code == 0:
                got = k.inverse(T, configuration=name)
                np.testing.assert_array_equal(got, json.loads(out)["q"])
                assert k.configuration_of(got) == name
            else:
                assert code == 3, err  # unreachable in that configuration
                with pytest.raises(rccx.UnreachableError) as e:
                    k.inverse(T, configuration=name)
                assert str(e.value) == err.strip()


def test_unreachable_raises_the_commands_message():
    k = rccx.kin.robot("puma560")
    T = np.eye(4)
    T[:3, 3] = [3.0, 0.0, 0.0]  # 3 m out: beyond the PUMA's 0.9 m reach
    code, _, err = cli("kin", "ik", "--robot", "puma560", "--T", numbers(T[:3].ravel()))
    assert code == 3
    with pytest.raises(rccx.UnreachableError) as e:
        k.inverse(T)
    assert str(e.value) == err.strip()
    assert isinstance(e.value, ValueError)
    with pytest.raises(rccx.UnreachableError):
        k.inverse_all(T)


def test_redundant_holds_joint_7_as_the_command_does():
    k = rccx.kin.robot("panda")
    T = k.forward(k.ready)
    out = cli_json("kin", "ik", "--robot", "panda", "--T", numbers(T[:3].ravel()),
                   "--redundant", "0.3", "--json")
    got = k.inverse(T, redundant=0.3)
    np.testing.assert_array_equal(got, out["q"])
    assert got[6] == pytest.approx(0.3, abs=1e-12)


@pytest.mark.parametrize("which", BUILTIN + URDFS)
def test_vectorised_equals_per_call(which):
    k, _ = robot_args(which)
    Q = random_joints(k, 257, seed=29)
    Ts = k.forward(Q)
    assert Ts.shape == (257, 4, 4)
    np.testing.assert_array_equal(Ts, np.stack([k.forward(q) for q in Q]))
    Js = k.jacobian(Q)
    assert Js.shape == (257, 6, k.dof)
    np.testing.assert_array_equal(Js, np.stack([k.jacobian(q) for q in Q]))
    assert k.forward(np.empty((0, k.dof))).shape == (0, 4, 4)
    # Any layout and number type of the same values gives the same answer.
    np.testing.assert_array_equal(k.forward(np.asfortranarray(Q)), Ts)
    np.testing.assert_array_equal(k.forward(np.hstack([Q, Q])[:, : k.dof]), Ts)
    np.testing.assert_array_equal(k.forward(Q[0].tolist()), Ts[0])
    np.testing.assert_array_equal(k.forward(np.zeros(k.dof, dtype=int)),
                                  k.forward(np.zeros(k.dof)))


@pytest.mark.parametrize("which", BUILTIN + URDFS)
def test_jacobian_is_the_derivative_of_forward(which):
    # Central differences of forward (independent of the Jacobian's code): linear rows from the
    # position, angular rows from the rotation's change (R' R^T)'s skew part.
    k, _ = robot_args(which)
    h = 1e-6
    for q in random_joints(k, 3, seed=30):
        J = k.jacobian(q)
        for i in range(k.dof):
            dq = np.zeros(k.dof)
            dq[i] = h
            Tp, Tm = k.forward(q + dq), k.forward(q - dq)
            v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
            W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ k.forward(q)[:3, :3].T
            w = np.array([W[2, 1], W[0, 2], W[1, 0]])
            np.testing.assert_allclose(J[:3, i], v, atol=1e-7)
            np.testing.assert_allclose(J[3:, i], w, atol=1e-7)


def test_robot_files_load_as_the_builtins():
    for name in ["puma560", "ur5e", "panda"]:
        k = rccx.kin.robot_file(ROBOTS_DIR / f"{name}.json")
        b = rccx.kin.robot(name)
        assert k.name == b.name and k.dof == b.dof
        Q = random_joints(b, 16, seed=31)
        np.testing.assert_array_equal(k.forward(Q), b.forward(Q))
    # robots/puma560.urdf is the DH PUMA 560 as a chain (docs/KINEMATICS.md).
    u, d = rccx.kin.urdf(str(ROBOTS_DIR / "puma560.urdf")), rccx.kin.robot("puma560")
    Q = random_joints(d, 64, seed=32)
    np.testing.assert_allclose(u.forward(Q), d.forward(Q), atol=1e-12)


def test_urdf_links_choose_the_chain():
    full = rccx.kin.urdf(ROBOTS_DIR / "panda.urdf")
    to7 = rccx.kin.urdf(ROBOTS_DIR / "panda.urdf", base_link="panda_link0", tip_link="panda_link7")
    assert full.dof == to7.dof == 7
    code, out, err = cli("kin", "fk", "--urdf", ROBOTS_DIR / "panda.urdf", "--tip-link",
                         "panda_link7", "--json", "--", *map(repr, full.ready.tolist()))
    assert code == 0, err
    np.testing.assert_array_equal(to7.forward(full.ready), np.array(json.loads(out)["T"]))
