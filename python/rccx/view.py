"""The web page of robots at work (`rccx view`), served from the Python program that drives them.

    import rccx
    with rccx.Robot("puma560") as robot, rccx.view.serve(robot, port=0) as view:
        print(view.url)                       # open it in a browser
        robot.move(rccx.joints("A", robot.kinematics.ready + 0.3))
        robot.waitfor(robot.completed())

serve takes a rccx.Robot, a cell's robot (cell.robot(name)) or a rccx.Cell. The page draws the
robots as they move and the goal of every position they move to; the sample loop only copies
samples for it (C++ rccx::view::serve, docs/VIEW.md).
"""

import os
import pathlib

from ._rccx import ViewError
from ._rccx.view import Server, find_assets
from ._rccx.view import serve as _serve

__all__ = ["Server", "ViewError", "find_assets", "serve"]


def _installed_assets():
    """<prefix>/share/rccx/web of an installed package (<prefix>/lib/python3.X/.../rccx), which
    the C++ search (beside the executable: python3's) does not look at; None when absent."""
    here = pathlib.Path(__file__).resolve().parent
    for prefix in list(here.parents)[:6]:
        d = prefix / "share" / "rccx" / "web"
        if (d / "index.html").is_file():
            return d
    return None


def serve(target, port=8080, *, address="127.0.0.1", rate=50.0, announce=True, assets=None):
    """Serves the page of `target` (a rccx.Robot, cell.robot(name) or a rccx.Cell) at
    http://address:port/ until the Server is closed; port 0: any free port (Server.port).
    rate: samples a second sent to the page (1 .. 200 Hz); announce: say the address on stderr;
    assets: the front end's folder (None: RCCX_VIEW_ASSETS, the build tree, the install).
    Raises rccx.ViewError (port in use, a robot another view serves), rccx.SessionError (closed)."""
    if assets is None and not os.environ.get("RCCX_VIEW_ASSETS") and find_assets() is None:
        assets = _installed_assets()
    return _serve(target, port, address=address, rate=rate, announce=announce, assets=assets)
