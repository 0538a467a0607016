"""Bad arguments to rccx.kin raise a clear Python exception carrying rccx's message, change
nothing and crash nothing (this runs under AddressSanitizer in the Debug build)."""

import math

import numpy as np
import pytest

from _support import ROBOTS_DIR, import_rccx

rccx = import_rccx()


@pytest.fixture(name="puma")
def fixture_puma():
    return rccx.kin.robot("puma560")


def test_unknown_robot_is_a_key_error_listing_the_known(puma):
    with pytest.raises(KeyError, match='no robot named "pumaa".*puma560'):
        rccx.kin.robot("pumaa")


def test_missing_and_bad_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.json"):
        rccx.kin.robot_file(tmp_path / "nope.json")
    with pytest.raises(FileNotFoundError, match="nope.urdf"):
        rccx.kin.urdf(tmp_path / "nope.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text('<robot name="r"><link name="a"/><joint name="j" type="floating">'
                   '<parent link="a"/><child link="b"/></joint><link name="b"/></robot>')
    with pytest.raises(rccx.RobotFileError, match="floating") as e:
        rccx.kin.urdf(bad)
    assert isinstance(e.value, ValueError)
    not_json = tmp_path / "r.json"
    not_json.write_text("{ not json")
    with pytest.raises(rccx.RobotFileError, match="r.json"):
        rccx.kin.robot_file(not_json)
    with pytest.raises(rccx.RobotFileError, match="no_such_link"):
        rccx.kin.urdf(ROBOTS_DIR / "ur5e.urdf", tip_link="no_such_link")


@pytest.mark.parametrize("q", [[0.0] * 5, [0.0] * 7, [[[0.0] * 6]], 0.0, []])
def test_joint_shapes(puma, q):
    with pytest.raises(ValueError, match=r"shape \(6,\).*puma560"):
        puma.forward(q)
    with pytest.raises(ValueError, match=r"shape \(6,\)"):
        puma.jacobian(q)


def test_batch_shape_names_the_row_count(puma):
    with pytest.raises(ValueError, match=r"\(N, 6\).*got shape \(4, 5\)"):
        puma.forward(np.zeros((4, 5)))


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_joints(puma, bad):
    q = np.array(puma.ready)
    q[2] = bad
    with pytest.raises(ValueError, match="not finite"):
        puma.forward(q)
    Q = np.zeros((5, 6))
    Q[3, 1] = bad
    before = Q.copy()
    with pytest.raises(ValueError, match=r"q\[3\] has a non-finite value"):
        puma.forward(Q)
    with pytest.raises(ValueError, match=r"q\[3\]"):
        puma.jacobian(Q)
    np.testing.assert_array_equal(Q, before)  # nothing written into the argument
    with pytest.raises(ValueError, match="near"):
        puma.inverse(puma.forward(puma.ready), near=q)


def test_bad_transforms(puma):
    T = puma.forward(puma.ready)
    for shape in [(3, 4), (4,), (16,), (2, 4, 4)]:
        with pytest.raises(ValueError, match=r"\(4, 4\)"):
            puma.inverse(np.zeros(shape))
    nan = T.copy()
    nan[0, 3] = math.nan
    with pytest.raises(ValueError, match="non-finite"):
        puma.inverse(nan)
    last = T.copy()
    last[3, 3] = 2.0
    with pytest.raises(ValueError, match="last row"):
        puma.inverse_all(last)
    sheared = T.copy()
    sheared[0, 1] += 0.1
    with pytest.raises(ValueError, match="not a rotation matrix"):
        puma.inverse(sheared)
    mirrored = T.copy()
    mirrored[:3, 0] *= -1  # det -1: left-handed
    with pytest.raises(ValueError, match="not a rotation matrix"):
        puma.inverse(mirrored)
    with pytest.raises(TypeError):
        puma.inverse("T")


def test_bad_solver_options(puma):
    T = puma.forward(puma.ready)
    with pytest.raises(ValueError, match='no configuration "xyz"; use one of lun'):
        puma.inverse(T, configuration="xyz")
    with pytest.raises(ValueError, match="not a 7-axis arm"):
        puma.inverse(T, redundant=0.1)
    with pytest.raises(ValueError, match=r"shape \(6,\)"):
        puma.inverse(T, near=[0.0] * 5)
    stanford = rccx.kin.robot("stanford")
    if not stanford.configuration_names:  # solved numerically: no names to ask for
        with pytest.raises(ValueError, match="no named configurations"):
            stanford.inverse(stanford.forward(stanford.ready), configuration="lun")
    panda = rccx.kin.robot("panda")
    with pytest.raises(ValueError, match="redundant is not finite"):
        panda.inverse(panda.forward(panda.ready), redundant=math.nan)


def test_unreachable_is_a_value_error_and_the_object_still_works(puma):
    T = np.eye(4)
    T[0, 3] = 5.0
    with pytest.raises(ValueError, match="out of reach"):
        puma.inverse(T)
    assert issubclass(rccx.UnreachableError, ValueError)
    assert rccx.UnreachableError.__module__ == "rccx"
    q = puma.inverse(puma.forward(puma.ready))
    np.testing.assert_allclose(puma.forward(q), puma.forward(puma.ready), atol=1e-12)


def test_no_constructor_and_read_only_properties(puma):
    with pytest.raises(TypeError):
        rccx.kin.Kinematics()
    with pytest.raises(AttributeError):
        puma.dof = 3
