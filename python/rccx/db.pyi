import os
from dataclasses import dataclass
from typing import Iterable

import numpy as np
from numpy.typing import ArrayLike

@dataclass(frozen=True)
class Position:
    robot: str
    name: str
    T: np.ndarray
    """(4, 4) float64, m."""
    configuration: str
    note: str
    created_unix_s: int
    changed_unix_s: int

class PositionDb:
    @property
    def path(self) -> str: ...
    @property
    def closed(self) -> bool: ...
    @property
    def schema_version(self) -> int: ...
    def get(self, robot: str, name: str) -> Position | None: ...
    def __getitem__(self, key: tuple[str, str]) -> np.ndarray: ...
    def put(self, robot: str, name: str, T: ArrayLike, configuration: str = "",
            note: str = "") -> None:
        """Stores T ((4, 4), m); rccx.InvalidTransform when it is not rigid."""
    def put_all(self, positions: Iterable[Position | tuple]) -> None: ...
    def remove(self, robot: str, name: str) -> bool: ...
    def robots(self) -> list[str]: ...
    def list(self, robot: str | None = None, pattern: str = "*") -> list[Position]: ...
    def close(self) -> None: ...
    def __enter__(self) -> PositionDb: ...
    def __exit__(self, *exc: object) -> None: ...

def open(path: str | os.PathLike[str] | None = None, create: bool = True,
         wait_s: float = 5.0) -> PositionDb:
    """Opens the position database (default $RCCX_DB, else ./rccx.db)."""

__all__ = ["Position", "PositionDb", "open"]
