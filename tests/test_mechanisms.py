"""Closed-loop mechanisms: the free four-bar over 10 s, Grashof's classes, mobility and redundancy,
constraints in model files and on the command line."""

from __future__ import annotations

import runpy
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import mechsys as ms
from mechsys.cli import cli

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def four_bar():
    return runpy.run_path(str(EXAMPLES / "four_bar.py"))["model"]


def test_free_four_bar_keeps_its_loop_closed_and_its_energy_for_10_s():
    res = ms.simulate(four_bar(), 10.0, ms.DOPRI5(rtol=1e-11, atol=1e-12), output_dt=0.01)
    assert np.abs(res["constraint/b/violation"]).max() < 1e-10
    e = res["energy/total"]
    assert np.ptp(e) / np.abs(e).max() < 1e-8
    # Freudenstein holds along the whole motion, independent of the dynamics
    a, b, c, d = 0.1, 0.3, 0.25, 0.28
    th2, th4 = res["joint/o2/q"], res["joint/o4/q"]
    k1, k2, k3 = d / a, d / c, (a**2 - b**2 + c**2 + d**2) / (2 * a * c)
    np.testing.assert_allclose(k1 * np.cos(th4) - k2 * np.cos(th2) + k3, np.cos(th2 - th4), atol=1e-10)


@pytest.mark.parametrize(
    "lengths, kind",
    [
        ((1.0, 3.0, 2.5, 2.8), "crank-rocker"),
        ((2.8, 3.0, 2.5, 1.0), "double crank (drag link)"),
        ((2.8, 1.0, 2.5, 3.0), "double rocker (Grashof)"),
        ((3.0, 3.0, 3.0, 4.0), "triple rocker (non-Grashof)"),
        ((1.0, 2.0, 2.0, 1.0), "change point"),
    ],
)
def test_grashof_classes(lengths, kind):
    assert ms.mechanisms.grashof(*lengths) == kind


def test_mobility_counts_degrees_of_freedom_and_names_redundant_equations():
    # the example is a planar model: its loop closure holds the 2 in-plane equations
    planar = four_bar()
    mob = ms.mechanisms.mobility(planar)
    assert (mob["nu"], mob["nc"], mob["rank"], mob["dof"]) == (3, 2, 2, 1) and mob["redundant"] == []
    # built in 3-D: three revolute joints, one loop closure (2 independent equations of 3)
    spatial = four_bar()
    spatial.planar = False  # rebuilds: the setter invalidates the built model
    mob = ms.mechanisms.mobility(spatial)
    assert (mob["nu"], mob["nc"], mob["rank"], mob["dof"]) == (3, 3, 2, 1)
    assert mob["redundant"] == [("b", 2)]
    m = ms.Model("tree")
    b = m.add_body("b", 1.0, [0.1, 0.1, 0.1])
    m.add_joint(ms.joints.Spherical("s", m.ground, b))
    assert ms.mechanisms.mobility(m)["dof"] == 3


FOUR_BAR_TOML = """\
name = "four-bar"
gravity = [0.0, -9.81, 0.0]

[[bodies]]
name = "crank"
mass = 0.2
inertia = [1e-6, 1.7e-4, 1.7e-4]
com = [0.05, 0.0, 0.0]

[[bodies]]
name = "coupler"
mass = 0.4
inertia = [1e-6, 3e-3, 3e-3]
com = [0.15, 0.0, 0.0]

[[bodies]]
name = "rocker"
mass = 0.3
inertia = [1e-6, 1.6e-3, 1.6e-3]
com = [0.125, 0.0, 0.0]

[[joints]]
name = "o2"
type = "revolute"
parent = "ground"
child = "crank"
q0 = [0.3]

[[joints]]
name = "a"
type = "revolute"
parent = "crank"
child = "coupler"
parent_frame = { position = [0.1, 0.0, 0.0] }
q0 = [0.9]

[[joints]]
name = "o4"
type = "revolute"
parent = "ground"
child = "rocker"
parent_frame = { position = [0.28, 0.0, 0.0] }
q0 = [1.9]

[[constraints]]
type = "point"
name = "b"
body1 = "coupler"
point1 = [0.3, 0.0, 0.0]
body2 = "rocker"
point2 = [0.25, 0.0, 0.0]

[simulation]
t_end = 0.5
output_dt = 0.01
integrator = { type = "dopri5", rtol = 1e-10, atol = 1e-12 }
"""


def test_constraints_in_model_files_and_on_the_command_line(tmp_path):
    path = tmp_path / "four_bar.toml"
    path.write_text(FOUR_BAR_TOML)
    runner = CliRunner()
    out = runner.invoke(cli, ["info", str(path)])
    assert out.exit_code == 0, out.output
    assert "constraints (1)" in out.output
    assert "DOF      1" in out.output
    assert "redundant" in out.output and "b[2]" in out.output
    h5 = tmp_path / "fb.h5"
    out = runner.invoke(cli, ["run", str(path), "--out", str(h5), "--quiet"])
    assert out.exit_code == 0, out.output
    res = ms.load(h5)
    assert np.abs(res["constraint/b/violation"]).max() < 1e-10
    # a misspelt key in a constraint is named with its path
    path.write_text(FOUR_BAR_TOML.replace('point1 = [0.3', 'pont1 = [0.3'))
    out = runner.invoke(cli, ["info", str(path)])
    assert out.exit_code == 2
    assert "constraints[0]" in out.output and "pont1" in out.output


def test_rolling_coin_example_runs_from_the_command_line(tmp_path):
    """The non-holonomic example as a model file: steady rolling keeps its lean and its energy."""
    h5 = tmp_path / "coin.h5"
    out = CliRunner().invoke(cli, ["run", str(EXAMPLES / "rolling_disc.py"), "--t-end", "1.0", "--out", str(h5), "--quiet"])
    assert out.exit_code == 0, out.output
    res = ms.load(h5)
    lean = np.arcsin(np.array([ms.kinematics.quat_to_matrix(q)[2, 2] for q in res["body/coin/orientation"]]))
    assert np.abs(lean - 0.3).max() < 1e-8
    e = res["energy/total"]
    assert np.ptp(e) < 1e-9 * np.abs(e).max()
