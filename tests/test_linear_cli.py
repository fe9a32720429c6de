"""``mechsys linear``: modes of the quarter-car example at its static equilibrium against the roots
of its characteristic polynomial, Bode and Campbell plots, and bad options named in the error."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from mechsys.cli import cli, main

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
QUARTER_CAR = EXAMPLES / "quarter_car.toml"
ROTOR = EXAMPLES / "rotor_campbell.py"
G = 9.81
MW, MB, KT, DT, KS, DS = 40.0, 300.0, 200000.0, 50.0, 20000.0, 1500.0  # the quarter car's data


@pytest.fixture(scope="module", autouse=True)
def _matplotlib_loaded():
    import matplotlib.backends.backend_agg  # noqa: F401


@pytest.fixture
def runner() -> CliRunner:
    return CliRunner()


def table(output: str) -> np.ndarray:
    """Rows (f_n, f_d, zeta) of the printed modes table."""
    rows = re.findall(r"^\s+\d+\s+(\S+)\s+(\S+)\s+(\S+)\s+\S+\s*$", output, flags=re.M)
    return np.array(rows, dtype=float)


def quarter_car_eigenvalues() -> np.ndarray:
    """Roots with Im >= 0 of det(M s^2 + D s + K) for M = diag(m_w, m_b), D and K of the tyre
    and suspension: (m_w s^2 + d11 s + k11)(m_b s^2 + d22 s + k22) - (d12 s + k12)^2."""
    k11, k22, k12 = KT + KS, KS, -KS
    d11, d22, d12 = DT + DS, DS, -DS
    coeffs = [MW * MB, MW * d22 + MB * d11, MW * k22 + MB * k11 + d11 * d22 - d12**2,
              d11 * k22 + d22 * k11 - 2 * d12 * k12, k11 * k22 - k12**2]
    s = np.roots(coeffs)
    s = s[s.imag > 0]
    return s[np.argsort(np.abs(s))]


def test_quarter_car_at_equilibrium(runner, tmp_path):
    result = runner.invoke(cli, ["linear", str(QUARTER_CAR), "--at", "equilibrium", "--frf", "wheel_y:body_y",
                                 "--out-dir", str(tmp_path)])
    assert result.exit_code == 0, (result.output, result.exception)
    out = result.stdout
    assert "warning" not in out and "stable" in out
    # the springs sag under the weights: q_w = -(m_w + m_b) g / k_t, q_b = q_w - m_b g / k_s
    qw = -(MW + MB) * G / KT
    qb = qw - MB * G / KS
    m = re.search(r"wheel_y = (\S+), body_y = (\S+)", out)
    np.testing.assert_allclose([float(m.group(1)), float(m.group(2))], [qw, qb], rtol=1e-5)
    rows = table(out)
    s = quarter_car_eigenvalues()
    np.testing.assert_allclose(rows[:, 0], np.abs(s) / (2 * np.pi), rtol=5e-6)  # six printed digits
    np.testing.assert_allclose(rows[:, 1], s.imag / (2 * np.pi), rtol=5e-6)
    np.testing.assert_allclose(rows[:, 2], -s.real / np.abs(s), rtol=5e-4)  # four printed digits
    png = tmp_path / "quarter-car_bode.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "wheel_y -> body_y, 500 frequencies" in out


def test_quarter_car_at_q0_reports_the_residual(runner, tmp_path):
    result = runner.invoke(cli, ["linear", str(QUARTER_CAR), "--out-dir", str(tmp_path), "--n", "50",
                                 "--fmin", "0.5", "--fmax", "20"])
    assert result.exit_code == 0, result.output
    assert "warning: " in result.stdout and "not an equilibrium" in result.stdout and "--at equilibrium" in result.stdout
    res = float(re.search(r"residual\s+(\S+)", result.stdout).group(1))
    assert res == pytest.approx(MB * G, rel=1e-3)  # the body's unbalanced weight at q0
    assert "0.5 .. 20 Hz" in result.stdout


def test_rotor_campbell_from_the_python_example(tmp_path):
    import io
    from contextlib import redirect_stdout

    buf = io.StringIO()
    with redirect_stdout(buf):
        code = main(["linear", str(ROTOR), "--campbell", "spin:0:600:61", "--whirl", "alpha,beta", "--out-dir", str(tmp_path)])
    out = buf.getvalue()
    assert code == 0, out
    assert (tmp_path / "rotor_campbell.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "rotor_bode.png").exists()
    ip, id_, kt = 0.02, 0.05, 2000.0
    crit = dict((w, float(v)) for v, w in re.findall(r"critical\s+(\S+) rad/s .*?(forward|backward) whirl", out))
    np.testing.assert_allclose(crit["backward"], np.sqrt(kt / (id_ + ip)), rtol=1e-3)
    np.testing.assert_allclose(crit["forward"], np.sqrt(kt / (id_ - ip)), rtol=1e-3)
    # standstill tilt frequency sqrt(k_t / I_d) / 2 pi (light damping, zeta = 0.0025)
    rows = table(out)
    np.testing.assert_allclose(rows[2:, 0], np.sqrt(kt / id_) / (2 * np.pi), rtol=1e-5)


@pytest.mark.parametrize(
    "args, fragments",
    [
        (["--frf", "wheel_y"], ["--frf: expected IN:OUT", "'wheel_y'"]),
        (["--frf", "wheel_y:axle"], ["--frf: no coordinate named 'axle'", "wheel_y, body_y"]),
        (["--frf", "0:7"], ["--frf: coordinate index 7 out of range 0..1"]),
        (["--fmin", "-1"], ["--fmin: must be a frequency > 0"]),
        (["--fmin", "10", "--fmax", "5"], ["--fmax (5 Hz) must be above --fmin (10 Hz)"]),
        (["--n", "1"], ["--n: need at least 2"]),
        (["--campbell", "spin:0:10"], ["--campbell: expected JOINT:START:STOP:N"]),
        (["--campbell", "spin:0:x:5"], ["--campbell: START and STOP must be numbers"]),
        (["--campbell", "spin:0:100:5"], ["--campbell: unknown joint 'spin'", "wheel_y, body_y"]),
        (["--campbell", "body_y:0:100:5", "--whirl", "wheel_y,hub"], ["--whirl: no coordinate named 'hub'"]),
        (["--whirl", "wheel_y,body_y"], ["--whirl: needs --campbell"]),
    ],
)
def test_bad_options_are_named(runner, tmp_path, args, fragments):
    result = runner.invoke(cli, ["linear", str(QUARTER_CAR), "--at", "equilibrium", "--out-dir", str(tmp_path), *args])
    assert result.exit_code == 2, (result.output, result.exception)
    err = result.stderr.strip()
    assert err.startswith("error: ") and "\n" not in err and "Traceback" not in result.output, err
    for f in fragments:
        assert f in err, (f, err)


def test_bad_at_and_missing_file(runner, tmp_path):
    result = runner.invoke(cli, ["linear", str(QUARTER_CAR), "--at", "rest"])
    assert result.exit_code == 2 and "--at" in result.stderr
    result = runner.invoke(cli, ["linear", str(tmp_path / "nope.toml")])
    assert result.exit_code == 2 and "nope.toml" in result.stderr


BICYCLE = EXAMPLES / "bicycle.py"


def test_linear_about_a_motion_on_the_command_line(runner, tmp_path):
    # the benchmark bicycle at 5 m/s: its published eigenvalues, the self-check and a speed sweep
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import bicycle_reference as bref

    r = runner.invoke(cli, ["linear", str(BICYCLE), "--coordinates", "free[3],steer", "--check",
                            "--sweep", "rear_hub':-12:-22:11", "--out-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "motion    steady; cyclic: free[0], free[1], free[5], rear_hub, front_hub" in r.output
    rows = re.findall(r"^\s+\d+\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", r.output.split("mode shapes")[0], flags=re.M)
    re_parts = np.sort(np.array([float(x[3]) for x in rows]))
    want = np.sort(np.unique(np.round(bref.eigenvalues(5.0).real, 9)))
    np.testing.assert_allclose(re_parts, want, rtol=1e-5)
    worst = float(re.search(r"worst relative difference (\S+)", r.output).group(1))
    assert worst < 1e-4
    # rear wheel -12 .. -22 rad/s is 3.6 .. 6.6 m/s: one stable range, between the weave and capsize speeds
    lo, hi = map(float, re.search(r"stable (\S+) \.\. (\S+):", r.output).groups())
    v1, v2 = sorted((-0.3 * lo, -0.3 * hi))
    assert v1 == pytest.approx(bref.weave_speed(), abs=0.02) and v2 == pytest.approx(bref.capsize_speed(), abs=0.02)
    assert (tmp_path / "bicycle_sweep.png").stat().st_size > 10_000


def test_linear_about_a_motion_bad_options(runner, tmp_path):
    r = runner.invoke(cli, ["linear", str(BICYCLE), "--coordinates", "free[0]", "--out-dir", str(tmp_path)])
    assert r.exit_code != 0 and "--coordinates" in r.output and "'free[0]' is cyclic" in r.output
    r = runner.invoke(cli, ["linear", str(BICYCLE), "--free", "steer", "--out-dir", str(tmp_path)])
    assert r.exit_code != 0 and "--free: needs --at steady" in r.output
    r = runner.invoke(cli, ["linear", str(BICYCLE), "--sweep", "rear_hub':0:1", "--out-dir", str(tmp_path)])
    assert r.exit_code != 0 and "--sweep: expected SPEED:START:STOP:N" in r.output


def test_linear_prints_the_mode_shapes(runner, tmp_path):
    # the quarter car: the body mode is mostly body_y, the wheel hop mostly wheel_y (newcomer 15)
    r = runner.invoke(cli, ["linear", str(QUARTER_CAR), "--at", "equilibrium", "--out-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    m1 = re.search(r"^\s+1\s+body_y 1, wheel_y (\S+) at", r.output, flags=re.M)
    m2 = re.search(r"^\s+2\s+wheel_y 1, body_y (\S+) at", r.output, flags=re.M)
    assert m1 and m2, r.output
    assert 0.01 < float(m1.group(1)) < 0.5 and 0.01 < float(m2.group(1)) < 0.5
