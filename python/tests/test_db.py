"""rccx.db against `rccx db` on the same file: what the command stores Python reads and the
reverse (its JSON export prints float64 to round-trip: equal to the last bit); list, remove,
robots; the context manager; another process holding the file (DatabaseBusy) while other
Python threads run."""

import json
import sqlite3
import threading
import time

import numpy as np
import pytest

from _support import cli, import_rccx, numbers, random_transform

rccx = import_rccx()


def rot_z(angle, p):
    c, s = np.cos(angle), np.sin(angle)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = p
    return T


def db_cli(path, *args):
    return cli("db", "--db", path, *args)


def exported(path):
    code, out, err = db_cli(path, "export")
    assert code == 0, err
    return {(t["robot"], t["name"]): t for t in json.loads(out)["transforms"]}


def T_of(entry):
    return np.vstack([np.array(entry["T_rows_m"]).reshape(3, 4), [0, 0, 0, 1]])


def test_what_rccx_db_stores_python_reads(tmp_path):
    path = tmp_path / "cell.db"
    rng = np.random.default_rng(27)
    given = {}
    for name in ["PICK", "PLACE", "P1"]:
        T = random_transform(rng)
        given[name] = T
        code, _, err = db_cli(path, "put", "--robot", "puma560", name, "--T",
                              numbers(T[:3].ravel()), "--config", "lun", "--note", f"n {name}")
        assert code == 0, err
    with rccx.db.open(path, create=False) as db:
        assert db.robots() == ["puma560"] and db.schema_version >= 1
        for name, T in given.items():
            p = db.get("puma560", name)
            assert (p.robot, p.name, p.configuration, p.note) == ("puma560", name, "lun",
                                                                  f"n {name}")
            assert p.T.shape == (4, 4) and p.T.dtype == np.float64
            np.testing.assert_array_equal(p.T, T)  # the same float64s, stored as REAL
            np.testing.assert_array_equal(db["puma560", name], T)
            assert p.created_unix_s > 0 and p.changed_unix_s >= p.created_unix_s
        assert [p.name for p in db.list()] == sorted(given)
        assert [p.name for p in db.list("puma560", "P*")] == ["P1", "PICK", "PLACE"]
        assert [p.name for p in db.list(pattern="P?")] == ["P1"]
        assert db.get("puma560", "NONE") is None and db.get("stanford", "PICK") is None
        with pytest.raises(KeyError, match="has no NONE for robot puma560"):
            db["puma560", "NONE"]
    assert db.closed


def test_what_python_stores_rccx_db_reads(tmp_path):
    path = tmp_path / "cell.db"
    rng = np.random.default_rng(28)
    stored = {("microbo", f"T{i}"): random_transform(rng) for i in range(5)}
    with rccx.db.open(path) as db:
        for (robot, name), T in stored.items():
            db.put(robot, name, T, configuration="n" if name == "T0" else "", note="from Python")
        db.put_all([("puma560", "A", rot_z(0.5, [0.1, 0.2, 0.3])),
                    ("puma560", "B", rot_z(-1.0, [0.4, 0.5, 0.6]), "rdf", "two")])
    stored[("puma560", "A")] = rot_z(0.5, [0.1, 0.2, 0.3])
    stored[("puma560", "B")] = rot_z(-1.0, [0.4, 0.5, 0.6])
    e = exported(path)
    assert set(e) == set(stored)
    for key, T in stored.items():
        np.testing.assert_array_equal(T_of(e[key]), T)
    assert e[("microbo", "T0")]["configuration"] == "n"
    assert e[("puma560", "B")]["note"] == "two"
    code, out, _ = db_cli(path, "list", "--robot", "puma560")
    assert code == 0 and [line.split(":")[0] for line in out.splitlines()] == ["puma560 A",
                                                                                 "puma560 B"]
    # Replacing keeps the created time; remove.
    with rccx.db.open(path) as db:
        created = db.get("puma560", "A").created_unix_s
        db.put("puma560", "A", rot_z(0.7, [0, 0, 0]))
        assert db.get("puma560", "A").created_unix_s == created
        assert db.remove("puma560", "B") and not db.remove("puma560", "B")
    np.testing.assert_array_equal(T_of(exported(path)[("puma560", "A")]), rot_z(0.7, [0, 0, 0]))
    code, _, err = db_cli(path, "show", "--robot", "puma560", "B")
    assert code == 2 and "has no B for robot puma560" in err


def test_the_default_file_is_rccx_dbs(tmp_path, monkeypatch):
    monkeypatch.setenv("RCCX_DB", str(tmp_path / "env.db"))
    with rccx.db.open() as db:
        db.put("stanford", "HOME", np.eye(4))
    assert (tmp_path / "env.db").exists()
    code, out, _ = cli("db", "list")  # the command reads $RCCX_DB too
    assert code == 0 and out.startswith("stanford HOME: x 0.000 y 0.000 z 0.000 mm")


def test_closed_and_context_manager(tmp_path):
    db = rccx.db.open(tmp_path / "c.db")
    assert not db.closed and "c.db" in repr(db)
    db.close()
    db.close()  # twice is fine
    assert db.closed and "closed" in repr(db)
    for call in (lambda: db.get("puma560", "A"), lambda: db.put("puma560", "A", np.eye(4)),
                 db.robots, lambda: db.list(), lambda: db.remove("puma560", "A")):
        with pytest.raises(rccx.DatabaseError, match="is closed"):
            call()
    with pytest.raises(RuntimeError):
        with rccx.db.open(tmp_path / "c.db") as db2:
            raise RuntimeError("inside")
    assert db2.closed


def test_another_process_holding_the_file_is_busy(tmp_path):
    path = tmp_path / "busy.db"
    with rccx.db.open(path) as db:
        db.put("puma560", "A", np.eye(4))
    holder = sqlite3.connect(path, isolation_level=None)
    holder.execute("BEGIN EXCLUSIVE")
    try:
        # While the put waits for the lock, another Python thread keeps running (the GIL is
        # released).
        counts = [0]
        done = threading.Event()

        def spin():
            while not done.is_set():
                counts[0] += 1

        t = threading.Thread(target=spin)
        t.start()
        with rccx.db.open(path, wait_s=0.5) as db:
            start = time.monotonic()
            with pytest.raises(rccx.DatabaseBusy) as e:
                db.put("puma560", "B", np.eye(4))
            waited = time.monotonic() - start
            before = counts[0]
            time.sleep(0.05)
        done.set()
        t.join()
        assert isinstance(e.value, rccx.DatabaseError)
        assert waited >= 0.4, waited
        assert before > 1000, before
    finally:
        holder.execute("ROLLBACK")
        holder.close()
    assert set(exported(path)) == {("puma560", "A")}
