"""Kinematics.forward's one-configuration fast path (a float64 (dof,) array read in place) gives
what the converting path gives for every other input of the same values: lists, other dtypes,
byte orders and layouts, unaligned data, and the batch call's row; it checks as strictly (shape,
finite values) and returns a fresh (4, 4) float64 array. The poses themselves are checked
against the rccx command and PyKDL in test_kin.py and test_kin_kdl.py."""

import math

import numpy as np
import pytest

from _support import import_rccx, random_joints

rccx = import_rccx()


@pytest.fixture(name="puma", scope="module")
def fixture_puma():
    return rccx.kin.robot("puma560")


def unaligned(q):
    """q's values in a float64 array whose data is not 8-byte aligned."""
    raw = np.zeros(q.size * 8 + 1, dtype=np.uint8)
    a = raw[1:].view(np.float64)
    a[:] = q
    return a


def test_every_input_of_the_same_values_gives_the_same_pose(puma):
    for q in random_joints(puma, 20, seed=27):
        q = np.ascontiguousarray(q, dtype=np.float64)
        fast = puma.forward(q)
        assert fast.shape == (4, 4) and fast.dtype == np.float64 and fast.flags.writeable
        row = puma.forward(q[None, :])[0]  # the batch path, one row
        np.testing.assert_array_equal(fast, row)
        strided = np.zeros(2 * q.size)
        strided[::2] = q
        read_only = q.copy()
        read_only.flags.writeable = False
        for other in (q.tolist(), tuple(q), q.astype(">f8"), strided[::2], read_only,
                      unaligned(q), q.astype(np.longdouble)):
            np.testing.assert_array_equal(puma.forward(other), fast)
        # float32 rounds the values: its own pose, as the float64 of the rounded values.
        q32 = q.astype(np.float32)
        np.testing.assert_array_equal(puma.forward(q32), puma.forward(q32.astype(np.float64)))
        # A fresh result each call, the argument untouched.
        before = q.copy()
        fast[:] = 0
        np.testing.assert_array_equal(puma.forward(q), row)
        np.testing.assert_array_equal(q, before)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_fast_path_refuses_non_finite(puma, bad):
    q = np.array(puma.ready, dtype=np.float64)
    q[4] = bad
    with pytest.raises(ValueError, match="forward: a joint value is not finite"):
        puma.forward(q)
    with pytest.raises(ValueError, match="not finite"):
        puma.forward(q.tolist())


@pytest.mark.parametrize("shape", [(5,), (7,), (0,), (1, 6, 1), (6, 1)])
def test_fast_path_refuses_other_shapes(puma, shape):
    with pytest.raises(ValueError, match=r"shape \(6,\).*puma560"):
        puma.forward(np.zeros(shape))


def test_not_numbers_is_a_type_error(puma):
    with pytest.raises(TypeError, match="forward"):
        puma.forward("q")
    with pytest.raises(TypeError):
        puma.forward({"q": 0.0})
