import os
from types import TracebackType
from typing import Optional, Union

from . import ViewError as ViewError
from .motion import Arm, Cell, Position

class Server:
    """A running view (C++ rccx::view::Server); made by serve."""

    @property
    def url(self) -> str:
        """The page's address, http://ADDRESS:PORT/."""
    @property
    def port(self) -> int:
        """The TCP port it listens on."""
    @property
    def closed(self) -> bool: ...
    def stats(self) -> dict[str, int]:
        """samples_sent, samples_dropped, messages_dropped, pages, requests."""
    def show(self, position: Position, robot: int = 0) -> None:
        """Draws a position's goal for robot `robot` (0-based) of the view."""
    def close(self) -> None:
        """Stops the server and frees its port; the robots go on. Idempotent."""
    def __enter__(self) -> "Server": ...
    def __exit__(
        self,
        exc_type: Optional[type[BaseException]],
        exc: Optional[BaseException],
        tb: Optional[TracebackType],
    ) -> None: ...

def find_assets() -> Optional[os.PathLike[str]]:
    """The front end's folder served by default, or None when none was built."""

def serve(
    target: Union[Arm, Cell],
    port: int = 8080,
    *,
    address: str = "127.0.0.1",
    rate: float = 50.0,
    announce: bool = True,
    assets: Optional[Union[str, os.PathLike[str]]] = None,
) -> Server:
    """The page of a rccx.Robot, cell.robot(name) or rccx.Cell at http://address:port/ (port 0:
    any free one). Raises rccx.ViewError (port in use), rccx.SessionError (closed robot)."""

__all__ = ["Server", "ViewError", "find_assets", "serve"]
