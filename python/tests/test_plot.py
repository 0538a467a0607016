"""rccx.plot against `rccx plot` on the same log (the washer's, recorded by the C++ example):
the figures it prints and the panels of its SVG; the series against the log's columns read by
Python's csv module; the Matplotlib figures against the series (Agg backend)."""

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from _data_support import WORST, read_csv, rccx_plot, washer_log
from _support import import_rccx

rccx = import_rccx()
matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def washer(tmp_path_factory):
    directory = tmp_path_factory.mktemp("washer")
    path, _ = washer_log(directory)
    code, out, err = rccx_plot(path, directory / "washer.svg")
    assert code == 0, err
    return path, rccx.log.load(path), out, ET.parse(directory / "washer.svg").getroot()


def test_the_figures_are_rccx_plots(washer):
    path, log, out, svg = washer
    p = rccx.plot.series(log)
    # rccx plot: "LOG: robot NAME (MODEL), N samples, D s, worst path error W mm ..."
    m = re.search(r"(\d+) samples, ([0-9.]+) s, ", out)
    assert p.samples == int(m.group(1)) == len(log)
    assert f"{p.duration_s:.2f}" == m.group(2)
    assert f"{p.worst_path_error_m * 1e3:.3f}" == WORST.search(out).group(1)
    assert p.worst_path_error_m == log.path_errors_m().max()
    # The SVG's panel titles, tick labels aside, and its subtitle.
    titles = [g.find(f"{SVG}text").text for g in svg.iter(f"{SVG}g")]
    assert titles == [panel.title for panel in p.panels]
    texts = [t.text for t in svg.iter(f"{SVG}text")]
    assert any(t.startswith(f"{p.robot_title}: {p.samples} samples") for t in texts if t)
    for g, panel in zip(svg.iter(f"{SVG}g"), p.panels):
        labels = [t.text for t in g.iter(f"{SVG}text") if t.get("class") == "label"]
        assert labels == [panel.xlabel, panel.ylabel]
        assert len(g.findall(f"{SVG}polyline")) == len(panel.series)


def test_the_series_are_the_logs_columns(washer):
    path, log, _, _ = washer
    header, columns, rows = read_csv(path)
    table = np.array([[float(v) for v in r] for r in rows])
    dof = log.dof
    t = table[:, 0] - table[0, 0]
    k = rccx.kin.robot(header["robot"])
    joints, tool_path, speed, error = rccx.plot.series(log).panels
    assert joints.xlabel == "t s" and joints.ylabel == "deg / mm"
    for j in range(dof):
        scale = 1e3 if k.joint_units[j] == "m" else 180.0 / np.pi
        commanded, measured = joints.series[2 * j], joints.series[2 * j + 1]
        assert commanded.dashed and not measured.dashed
        assert measured.label == f"q{j + 1} {'mm' if k.joint_units[j] == 'm' else 'deg'}"
        np.testing.assert_array_equal(measured.x, t)
        np.testing.assert_array_equal(measured.y, table[:, 2 + dof + j] * scale)
        np.testing.assert_array_equal(commanded.y, table[:, 2 + j] * scale)
    # The tool path in the plane of the two coordinates the commanded tool spans most.
    p = table[:, 2 + 2 * dof:5 + 2 * dof]
    u, v = sorted(np.argsort(-(p.max(axis=0) - p.min(axis=0)), kind="stable")[:2])
    assert tool_path.xlabel == f"{'xyz'[u]} mm" and tool_path.ylabel == f"{'xyz'[v]} mm"
    assert tool_path.equal_axes
    np.testing.assert_array_equal(tool_path.series[0].x, p[:, u] * 1e3)
    np.testing.assert_array_equal(tool_path.series[0].y, p[:, v] * 1e3)
    pm = k.forward(table[:, 2 + dof:2 + 2 * dof])[:, :3, 3]
    np.testing.assert_allclose(tool_path.series[1].x, pm[:, u] * 1e3, rtol=0, atol=1e-9)
    # Speed along the path: the commanded tool's steps over the time steps, mm/s.
    expected = np.r_[0, np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(table[:, 0]) * 1e3]
    np.testing.assert_allclose(speed.series[0].y, expected, rtol=1e-12, atol=1e-9)
    assert speed.ylabel == "mm/s"
    np.testing.assert_array_equal(error.series[0].y, log.path_errors_m() * 1e3)
    assert error.ylabel == "mm"


def test_matplotlib_draws_the_series(washer, tmp_path):
    _, log, _, _ = washer
    p = rccx.plot.series(log)
    figs = rccx.plot.figures(log)
    assert len(figs) == 4
    for fig, panel in zip(figs, p.panels):
        (ax,) = fig.axes
        assert ax.get_title() == panel.title
        assert ax.get_xlabel() == panel.xlabel and ax.get_ylabel() == panel.ylabel
        lines = ax.get_lines()
        assert len(lines) == len(panel.series)
        for line, s in zip(lines, panel.series):
            np.testing.assert_array_equal(line.get_xdata(), s.x)
            np.testing.assert_array_equal(line.get_ydata(), s.y)
            assert line.get_linestyle() == ("--" if s.dashed else "-")
    fig = rccx.plot.figure(log, title="washer")
    assert len(fig.axes) == 4
    assert f"{p.samples} samples" in fig._suptitle.get_text()
    fig.savefig(tmp_path / "washer.png", dpi=50)
    data = (tmp_path / "washer.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


def test_a_log_of_another_robot_cannot_be_plotted(washer):
    _, log, _, _ = washer
    with pytest.raises(rccx.RunLogError, match="is a log of robot microbo"):
        rccx.plot.figures(log, rccx.kin.robot("stanford"))
