"""Moreau-Jean's position projection of contacts that stay closed (MoreauJean(project=True)):
a disc rolling in a curved track does not sink into it, and still swings with the closed-form
period."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def track():
    spec = importlib.util.spec_from_file_location("ball_in_track", EXAMPLES / "ball_in_track.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_a_disc_rolling_in_a_curved_track_sinks_without_projection_and_not_with_it(track):
    plain = ms.simulate(track.model, t_end=6.0, integrator=ms.MoreauJean(dt=1e-3), output_dt=1e-2)
    held = ms.simulate(track.model, t_end=6.0, integrator=ms.MoreauJean(dt=1e-3, project=True), output_dt=1e-2)
    g0, g1 = plain["contact/track/g_n"], held["contact/track/g_n"]
    # the velocity-level scheme lets the rolling contact drift in by O(dt) per unit time, steadily
    assert g0[-1] < -3e-5 and g0[-1] < 1.5 * g0[len(g0) // 2]
    assert g1.min() > -1e-10
    # the swing keeps its closed-form period, T = 2 pi sqrt(3 (R0 - r) / (2 g)), and its energy
    expected = 2 * np.pi * np.sqrt(3 * (track.R0 - track.RADIUS) / (2 * track.G))
    assert abs(track.period(held) - expected) < 2e-3 * expected
    e0, e1 = plain["energy/total"], held["energy/total"]
    assert abs(e1[-1] - e1[0]) < 0.05 * abs(e0[-1] - e0[0])


def test_projection_from_a_model_file(tmp_path):
    from mechsys.modelfile import load_model, simulation_kwargs

    path = tmp_path / "bowl.toml"
    path.write_text("""
name = "bowl"
gravity = [0.0, 0.0, -9.81]
[[bodies]]
name = "ball"
mass = 1.0
inertia = [0.004, 0.004, 0.004]
[[joints]]
name = "free"
type = "free"
parent = "ground"
child = "ball"
q0 = [0.05, 0.0, -0.39686269665968863, 1.0, 0.0, 0.0, 0.0]
[[contacts]]
name = "bowl"
body1 = "ball"
contour1 = { type = "sphere", radius = 0.1 }
body2 = "ground"
contour2 = { type = "bowl", radius = 0.5 }
friction = { type = "coulomb", mu = 0.8 }
[simulation]
t_end = 2.0
integrator = { type = "moreau_jean", dt = 1e-3, project = true }
""")
    model, sim = load_model(path)
    kwargs = simulation_kwargs(sim)
    assert kwargs["integrator"].project is True
    res = ms.simulate(model, **kwargs)
    assert res["contact/bowl/g_n"].min() > -1e-10
    assert res["contact/bowl/lambda_n"][-1] > 5.0  # it rests on the bowl
