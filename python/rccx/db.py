"""The position database (C++ rccx::rccl::PositionDb, the file `rccx db` reads and writes):
named transforms per robot, on SQLite, every write one transaction.

    import numpy as np, rccx
    with rccx.db.open("cell.db") as db:                  # closed at the end of the block
        db.put("puma560", "PICK", T, configuration="lun", note="over the tray")  # T (4, 4), m
        p = db.get("puma560", "PICK")                    # rccx.db.Position, or None
        p.T                                              # (4, 4) float64, m
        for p in db.list("puma560", "P*"): ...
        db.remove("puma560", "PICK")

Names of transforms and robots: 1 to 32 letters, digits and _ - . ; a configuration up to 8
letters; a note UTF-8 without control characters, up to 1000 bytes. A transform is rigid:
finite, its rotation orthonormal and right-handed (1e-6), its position within 100 m of the
origin on each axis. Anything else raises rccx.InvalidTransform (a ValueError and a
rccx.DatabaseError) and nothing is stored. Unlike `rccx db put`, any valid robot name is
taken (the command refuses robots it does not know unless --new-robot names them).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Iterable

import numpy as np

from . import _rccx

__all__ = ["Position", "PositionDb", "open"]


@dataclass(frozen=True)
class Position:
    """One stored transform (C++ rccl::StoredTransform)."""
    robot: str
    name: str
    T: np.ndarray         # (4, 4) float64: rotation columns n o a, position m
    configuration: str    # the arm configuration it was taught in ("lun"), or ""
    note: str
    created_unix_s: int   # when first stored, s since 1970
    changed_unix_s: int   # when last stored


def _position(t: tuple) -> Position:
    t[2].flags.writeable = False  # a Position is a value; copy T to change it
    return Position(*t)


class PositionDb:
    """An open position database. Made by rccx.db.open; a context manager that closes it.

    Every call releases the GIL (a write may wait for another process up to wait_s) and the
    object may be shared by threads. Errors: rccx.DatabaseError (a RuntimeError) for a
    database that cannot be used or is closed, rccx.DatabaseBusy when another process held it
    longer than wait_s, rccx.InvalidTransform for a bad name, robot or transform; rccx's
    messages, nothing changed."""

    def __init__(self, data: _rccx.db.PositionDbData) -> None:
        self._data = data

    @property
    def path(self) -> str:
        return self._data.path

    @property
    def closed(self) -> bool:
        return self._data.closed

    @property
    def schema_version(self) -> int:
        """The schema version in the file (C++ PositionDb::schema_version)."""
        return self._data.schema_version()

    def get(self, robot: str, name: str) -> Position | None:
        """The transform name of robot, or None when it is not stored."""
        t = self._data.get(robot, name)
        return None if t is None else _position(t)

    def __getitem__(self, key: tuple[str, str]) -> np.ndarray:
        """db["puma560", "PICK"]: the transform's T (4, 4), m; KeyError when not stored."""
        robot, name = key
        p = self.get(robot, name)
        if p is None:
            raise KeyError(f"{self.path} has no {name} for robot {robot}")
        return p.T

    def put(self, robot: str, name: str, T, configuration: str = "", note: str = "") -> None:
        """Stores T ((4, 4), m) as name of robot, replacing one of that name (its created time
        kept), in one transaction."""
        self._data.put(robot, name, T, configuration, note)

    def put_all(self, positions: Iterable[Position | tuple]) -> None:
        """Stores them all in one transaction, every one or none (each checked first): Position
        objects or (robot, name, T[, configuration[, note]]) tuples."""
        rows = []
        for p in positions:
            if isinstance(p, Position):
                rows.append((p.robot, p.name, p.T, p.configuration, p.note))
            else:
                p = tuple(p)
                if not 3 <= len(p) <= 5:
                    raise ValueError("put_all: give (robot, name, T[, configuration[, note]]) "
                                     f"tuples or Position objects, got {len(p)} items")
                rows.append(p + ("",) * (5 - len(p)))
        self._data.put_all(rows)

    def remove(self, robot: str, name: str) -> bool:
        """Removes the transform; False when there was none."""
        return self._data.remove(robot, name)

    def robots(self) -> list[str]:
        """The robots that have transforms stored, by name."""
        return self._data.robots()

    def list(self, robot: str | None = None, pattern: str = "*") -> list[Position]:
        """The transforms of robot (every robot when None) whose names match the glob pattern
        ("*", "P?", "PICK*"), by robot then name."""
        return [_position(t) for t in self._data.list(robot or "", pattern)]

    def close(self) -> None:
        """Closes the database (calls after raise rccx.DatabaseError); closing twice is fine."""
        self._data.close()

    def __enter__(self) -> PositionDb:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<rccx.db.PositionDb {self.path!r}{' closed' if self.closed else ''}>"


def open(path: str | os.PathLike[str] | None = None, create: bool = True,  # noqa: A001
         wait_s: float = 5.0) -> PositionDb:
    """Opens the position database at path (default: $RCCX_DB, else ./rccx.db, as `rccx db`).

    create: make the file when it is missing (else rccx.DatabaseError). wait_s: how long a call
    waits for another process writing the database before rccx.DatabaseBusy (0 .. 3600 s).
    Older files are migrated to this rccx's schema; a file of a newer rccx is refused."""
    if path is None:
        path = os.environ.get("RCCX_DB") or "rccx.db"
    return PositionDb(_rccx.db.PositionDbData(os.fspath(path), create, float(wait_s)))
