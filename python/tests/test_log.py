"""rccx.log against independent readings of the same run: the C++ washer example writes a log
(RCCX_LOG), Python's csv module reads it, `rccx plot` and the washer print its worst path
error; a log of `rccx report --log` for a robot of six revolute joints."""

import numpy as np
import pytest

from _data_support import WORST, read_csv, report_log, rccx_plot, washer_log
from _support import import_rccx

rccx = import_rccx()


@pytest.fixture(scope="module")
def washer(tmp_path_factory):
    path, stdout = washer_log(tmp_path_factory.mktemp("washer"))
    return path, stdout, rccx.log.load(path)


def check_against_csv(log, path):
    header, columns, rows = read_csv(path)
    dof = (len(columns) - 8) // 2
    assert log.dof == dof and len(log) == len(rows) and len(log.samples) == len(rows)
    s = log.samples
    assert s.dtype.names == ("t_s", "segment", "commanded", "measured", "p_m", "approach")
    assert s["commanded"].shape == (len(rows), dof) and s["p_m"].shape == (len(rows), 3)
    assert s["t_s"].dtype == np.float64 and s["segment"].dtype == np.int32
    table = np.array([[float(v) for v in r] for r in rows])
    # The same decimal text, parsed by C++ and by Python: both round correctly, so equal.
    np.testing.assert_array_equal(s["t_s"], table[:, 0])
    np.testing.assert_array_equal(s["segment"], [int(r[1]) for r in rows])
    np.testing.assert_array_equal(s["commanded"], table[:, 2:2 + dof])
    np.testing.assert_array_equal(s["measured"], table[:, 2 + dof:2 + 2 * dof])
    np.testing.assert_array_equal(s["p_m"], table[:, 2 + 2 * dof:5 + 2 * dof])
    np.testing.assert_array_equal(s["approach"], table[:, 5 + 2 * dof:8 + 2 * dof])
    assert columns[2] == "q1" and columns[2 + dof] == "qm1"
    return header


def test_the_washers_log_is_its_csv(washer):
    path, _, log = washer
    header = check_against_csv(log, path)
    assert log.has_header and log.robot_name == header["robot"] == "microbo"
    assert log.name == header["name"] and log.kinematics == header["kinematics"]
    assert log.period_s == pytest.approx(int(header["period_ns"]) * 1e-9, rel=0, abs=0)
    assert log.simulated == (header["clock"] == "simulated")
    assert log.rccx_version == header["rccx"]
    assert log.path == str(path)
    assert "microbo" in repr(log)
    # Read-only: the log as read.
    with pytest.raises(ValueError):
        log.samples["t_s"][0] = 1.0


def test_the_path_error_is_rccx_plots_and_the_washers(washer, tmp_path):
    path, stdout, log = washer
    errors = log.path_errors_m()
    assert errors.shape == (len(log),) and np.all(errors >= 0)
    code, out, err = rccx_plot(path, tmp_path / "w.svg")
    assert code == 0, err
    plot_mm = WORST.search(out).group(1)
    assert f"{errors.max() * 1e3:.3f}" == plot_mm
    # The washer prints the same figure of its own log.
    assert f"log {path}: worst path error {plot_mm} mm" in stdout


def test_the_path_error_against_numpy(washer):
    """The path error recomputed here: the measured tool point (forward kinematics of the
    measured joints) to the nearest point of the commanded polyline from 600 samples before to
    50 after (view::path_errors_m's definition)."""
    _, _, log = washer
    k = rccx.kin.robot(log.robot_name)
    s = log.samples
    pm = k.forward(s["measured"])[:, :3, 3]
    pc = s["p_m"]
    n = len(s)
    errors = log.path_errors_m()
    for i in np.linspace(0, n - 1, 60).astype(int):
        lo, hi = max(0, i - 600), min(n - 1, i + 50)
        a, b = pc[lo:hi], pc[lo + 1:hi + 1]
        d = b - a
        len2 = np.einsum("ij,ij->i", d, d)
        t = np.where(len2 > 0, np.clip(np.einsum("ij,ij->i", pm[i] - a, d) / np.where(
            len2 > 0, len2, 1), 0, 1), 0)
        e = min(np.linalg.norm(pm[i] - pc[i]), np.min(np.linalg.norm(a + d * t[:, None] - pm[i],
                                                                    axis=1), initial=np.inf))
        assert errors[i] == pytest.approx(e, abs=1e-12)


def test_a_puma_log_of_the_rccx_command(tmp_path):
    path = report_log(tmp_path, "puma560", "0.5")
    log = rccx.log.load(path)
    header = check_against_csv(log, path)
    assert log.dof == 6 and log.robot_name == "puma560" == header["robot"]
    assert log.period_s == pytest.approx(0.01, rel=1e-12)
    assert log.robot().name == "puma560"
    # Holding still: commanded and measured tool stay put.
    assert np.all(log.path_errors_m() < 1e-3)


def test_a_log_without_header_needs_its_robot(washer, tmp_path):
    path, _, log = washer
    old = tmp_path / "old.csv"
    old.write_text("".join(path.read_text().splitlines(keepends=True)[1:]))
    o = rccx.log.load(old)
    assert not o.has_header and o.robot_name is None and o.period_s is None
    np.testing.assert_array_equal(o.samples, log.samples)
    with pytest.raises(rccx.RunLogError, match="no header line naming its robot"):
        o.path_errors_m()
    np.testing.assert_array_equal(o.path_errors_m(rccx.kin.robot("microbo")), log.path_errors_m())
    # Another robot than the header's is refused, as `rccx plot --robot` is.
    with pytest.raises(rccx.RunLogError, match="is a log of robot microbo"):
        log.path_errors_m(rccx.kin.robot("puma560"))
    with pytest.raises(rccx.RunLogError, match="the log has 6 joints, robot panda has 7"):
        o.path_errors_m(rccx.kin.robot("panda"))
