"""Bad input to rccx.db raises, with rccx's message (the same as `rccx db`'s where the command
takes the same input), and changes nothing: no file made, the stored values as they were."""

import json

import numpy as np
import pytest

from _support import cli, import_rccx, numbers

rccx = import_rccx()


def export_text(path):
    code, out, err = cli("db", "--db", path, "export")
    assert code == 0, err
    return json.loads(out)["transforms"]


@pytest.fixture()
def db_file(tmp_path):
    path = tmp_path / "cell.db"
    with rccx.db.open(path) as db:
        db.put("puma560", "KEEP", np.eye(4), note="as it was")
    return path


def not_rigid():
    T = np.eye(4)
    T[0, 1] = 0.1
    return T


def mirrored():
    return np.diag([1.0, 1.0, -1.0, 1.0])


def far():
    T = np.eye(4)
    T[0, 3] = 200.0
    return T


def with_nan():
    T = np.eye(4)
    T[1, 3] = np.nan
    return T


BAD_VALUES = {
    "not_rigid": (not_rigid, "not a rigid transform"),
    "mirrored": (mirrored, "not a rigid transform"),
    "far": (far, "beyond 100 m of the origin"),
    "nan": (with_nan, "non-finite"),
    "shape": (lambda: np.eye(3), r"must be a \(4, 4\) homogeneous transform \(m\), got shape \(3, 3\)"),
    "last_row": (lambda: np.ones((4, 4)), "last row must be 0 0 0 1"),
    "not_numbers": (lambda: [["a"] * 4] * 4, None),  # a TypeError: not numbers at all
}


@pytest.mark.parametrize("case", sorted(BAD_VALUES))
def test_a_bad_transform_stores_nothing(case, db_file):
    make, message = BAD_VALUES[case]
    before = export_text(db_file)
    with rccx.db.open(db_file) as db:
        with pytest.raises(TypeError if message is None else ValueError) as e:
            db.put("puma560", "KEEP", make())
        if message is not None:
            assert isinstance(e.value, rccx.InvalidTransform)
            assert isinstance(e.value, rccx.DatabaseError)
            assert e.value.args[0].startswith('transform "KEEP": ')
            assert e.match(message)
        with pytest.raises(TypeError if message is None else ValueError):  # all or none
            db.put_all([("puma560", "NEW", np.eye(4)), ("puma560", "KEEP", make())])
    assert export_text(db_file) == before


@pytest.mark.parametrize("T,key", [(far(), "100"), (not_rigid(), "orthonormal")])
def test_the_messages_are_rccx_dbs(T, key, db_file):
    """The command refuses the same transform (exit 2), naming the same fault."""
    with rccx.db.open(db_file) as db, pytest.raises(rccx.InvalidTransform) as e:
        db.put("puma560", "X", T)
    code, _, err = cli("db", "--db", db_file, "put", "--robot", "puma560", "X", "--T",
                       numbers(T[:3].ravel()))
    assert code == 2
    assert key in err and key in str(e.value)


BAD_NAMES = [("puma560", "", "is empty"), ("puma560", "a b", "transform name"),
             ("puma560", "x" * 33, "transform name"), ("bad robot", "A", "robot name"),
             ("puma560", "ÄB", "transform name")]


@pytest.mark.parametrize("robot,name,message", BAD_NAMES)
def test_a_bad_name_is_refused(robot, name, message, db_file):
    before = export_text(db_file)
    with rccx.db.open(db_file) as db:
        for call in (lambda: db.put(robot, name, np.eye(4)), lambda: db.get(robot, name),
                     lambda: db.remove(robot, name)):
            with pytest.raises(rccx.InvalidTransform, match=message) as e:
                call()
    assert export_text(db_file) == before
    if name:  # the command says the same of the name (after what it names: --robot ...)
        code, _, err = cli("db", "--db", db_file, "show", "--robot", robot, name)
        assert code == 2 and str(e.value).split(": ", 1)[1] in err


def test_bad_configuration_and_note(db_file):
    with rccx.db.open(db_file) as db:
        with pytest.raises(rccx.InvalidTransform, match="configuration"):
            db.put("puma560", "X", np.eye(4), configuration="l1")
        with pytest.raises(rccx.InvalidTransform, match="note"):
            db.put("puma560", "X", np.eye(4), note="two\nlines")
        with pytest.raises(ValueError, match="put_all"):
            db.put_all([("puma560",)])
        assert db.get("puma560", "X") is None


def test_a_missing_file_is_not_made(tmp_path):
    path = tmp_path / "none.db"
    with pytest.raises(rccx.DatabaseError, match="does not exist"):
        rccx.db.open(path, create=False)
    assert not path.exists()
    code, _, err = cli("db", "--db", path, "show", "--robot", "puma560", "A")
    assert not path.exists()


def test_not_a_database(tmp_path):
    path = tmp_path / "text.db"
    path.write_text("not sqlite at all, " * 100)
    before = path.read_bytes()
    with pytest.raises(rccx.DatabaseError) as e:
        rccx.db.open(path)
    code, _, err = cli("db", "--db", path, "list")
    assert code == 1 and err.splitlines()[0] == f"error: {e.value}"
    assert path.read_bytes() == before
    with pytest.raises(rccx.DatabaseError, match="is a directory"):
        rccx.db.open(tmp_path)


def test_bad_wait(tmp_path):
    for wait in (-1, float("nan"), 1e9):
        with pytest.raises(ValueError, match="wait_s"):
            rccx.db.open(tmp_path / "w.db", wait_s=wait)
    assert not (tmp_path / "w.db").exists()
