"""Position equations from Python against NumPy's products of the same matrices (an independent
result): the operators, the inverses moved across, the tool, the call form, and malformed
equations raising rccx.EquationError with rccx's message."""

import numpy as np
import pytest

from _support import import_rccx, random_transform

rccx = import_rccx()


def rigid(seed):
    """A random rigid transform (4, 4), m."""
    return random_transform(np.random.default_rng(seed), reach_m=0.5)


inv = np.linalg.inv


def test_operators_give_rccl_equation():
    T6 = rccx.t6()
    tool, base, conv, part = rigid(1), rigid(2), rigid(3), rigid(4)
    TOOL, BASE, CONV, PART = (rccx.const(n, v) for n, v in
                              (("TOOL", tool), ("BASE", base), ("CONV", conv), ("PART", part)))
    p = rccx.position("P", T6 * TOOL == BASE.inv() * CONV * PART)
    assert p.describe() == "P: BASE T6 TOOL = CONV PART (tool TOOL)"
    np.testing.assert_allclose(p.t6(), inv(base) @ conv @ part @ inv(tool), atol=1e-12)
    np.testing.assert_allclose(p.tool(), tool, atol=1e-15)
    # The same equation, written the other way round and in the call form.
    q = rccx.position("Q", BASE.inv() * CONV * PART == T6 * TOOL)
    r = rccx.position("R", lhs=[BASE, T6, TOOL], rhs=[CONV, PART], tool=TOOL)
    for x in (q, r):
        assert x.describe().split(": ", 1)[1] == p.describe().split(": ", 1)[1]
        np.testing.assert_allclose(x.t6(), p.t6(), atol=1e-12)


def test_trailing_inverse_and_explicit_tool():
    T6 = rccx.t6()
    a, b, g = rigid(5), rigid(6), rigid(7)
    A, B, G = rccx.const("A", a), rccx.const("B", b), rccx.const("G", g)
    p = rccx.position("P", T6 * G == A * B.inv())  # T6 G B = A, tool G as written
    assert p.describe() == "P: T6 G B = A (tool G)"
    np.testing.assert_allclose(p.t6(), a @ inv(b) @ inv(g), atol=1e-12)
    p2 = rccx.position("P2", T6 * G * B == A, tool=T6)
    np.testing.assert_allclose(p2.tool(), np.eye(4), atol=0)
    np.testing.assert_allclose(p2.t6(), p.t6(), atol=1e-12)


def test_hold_set_reaches_t6():
    T6 = rccx.t6()
    h = rccx.hold("H", rigid(8))
    p = rccx.position("P", T6 == h)
    np.testing.assert_allclose(p.t6(), rigid(8), atol=1e-15)
    h.set(rigid(9))
    np.testing.assert_allclose(h.value, rigid(9), atol=0)
    np.testing.assert_allclose(p.t6(), rigid(9), atol=1e-15)
    with pytest.raises(TypeError, match="only a hold"):
        rccx.const("C", rigid(1)).set(rigid(2))


def test_stream_newest_and_age():
    s = rccx.stream("S", rigid(10))
    assert s.kind == "functional" and s.age is None and s.count == 0
    np.testing.assert_array_equal(s.value, rigid(10))
    s.put(rigid(11))
    np.testing.assert_array_equal(s.value, rigid(11))
    np.testing.assert_array_equal(s.newest, rigid(11))
    assert 0 <= s.age < 5 and s.count == 1
    p = rccx.position("P", rccx.t6() == s)
    assert p.moves
    with pytest.raises(ValueError, match="functional"):
        p.t6()


def test_stream_put_with_time_and_velocity_and_its_errors():
    s = rccx.stream("S", rigid(10))
    assert s.max_extrapolation == 0.25
    s.put(rigid(11), at=2.0, velocity=np.arange(6.0))
    # Outside a sample (planning) the value is the pose as put.
    np.testing.assert_array_equal(s.value, rigid(11))
    assert s.count == 1
    bad = [({"velocity": np.zeros(6)}, "needs at="),
           ({"at": float("nan")}, "finite"),
           ({"at": 1.0, "velocity": np.zeros(3)}, "6 finite values"),
           ({"at": 1.0, "velocity": [0, 0, float("inf"), 0, 0, 0]}, "6 finite values")]
    for kwargs, message in bad:
        with pytest.raises(ValueError, match=message):
            s.put(rigid(12), **kwargs)
    # A refused put changes nothing.
    assert s.count == 1
    np.testing.assert_array_equal(s.newest, rigid(11))
    for bad_s in (-0.1, float("nan"), 11.0):
        with pytest.raises(ValueError, match="max_extrapolation"):
            rccx.stream("S", max_extrapolation=bad_s)


def test_transforms_in_lists_keep_identity():
    a, b = rccx.const("A", np.eye(4)), rccx.const("B", np.eye(4))
    assert a in [a] and b not in [a] and a != b
    assert len({a, b, a}) == 2


@pytest.mark.parametrize("build, message", [
    (lambda T6, A, B: A == B, "T6"),
    (lambda T6, A, B: T6 * T6 == A, "more than once"),
    (lambda T6, A, B: T6 == A * B.inv() * A, "inside"),
    (lambda T6, A, B: T6.inv() == A, "inverted"),
])
def test_malformed_equations(build, message):
    T6, A, B = rccx.t6(), rccx.const("A", rigid(1)), rccx.const("B", rigid(2))
    with pytest.raises(rccx.EquationError, match=message) as e:
        rccx.position("BAD", build(T6, A, B))
    assert isinstance(e.value, ValueError)


def test_tool_not_on_left_side():
    T6, A, B = rccx.t6(), rccx.const("A", rigid(1)), rccx.const("B", rigid(2))
    with pytest.raises(ValueError, match="tool"):
        rccx.position("BAD", T6 == A * B, tool=A)


@pytest.mark.parametrize("value, message", [
    (np.eye(3), r"\(4, 4\)"),
    (np.full((4, 4), np.nan), "non-finite"),
    (np.diag([1.0, 1.0, 2.0, 1.0]), "rotation"),
    (np.diag([1.0, 1.0, 1.0, 2.0]), "last row"),
])
def test_bad_transforms(value, message):
    with pytest.raises(ValueError, match=message):
        rccx.const("X", value)
    with pytest.raises(ValueError, match=message):
        rccx.hold("H").set(value)
    with pytest.raises(ValueError, match=message):
        rccx.stream("S").put(value)


def test_joint_positions():
    p = rccx.joints("PARK", [0.1, 0.2, 0.3])
    assert p.in_joints
    np.testing.assert_array_equal(p.joints, [0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="non-finite"):
        rccx.joints("BAD", [0.0, np.nan])
    with pytest.raises(ValueError, match="shape"):
        rccx.joints("BAD", np.zeros((2, 3)))
