"""Warm-started contact searches of curved planar contours (issue 14): whole simulations give the
same results with ``warm_search=False`` (every evaluation searches from scratch), in both contact
schemes, above and below the cam's lift-off speed, and for the rattling gear pair."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms

ROOT = Path(__file__).resolve().parents[1]


def _example(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _same(a, b, what: str, tol: float = 1e-9):
    names = [n for n in a.names() if n.startswith(("joint/", "contact/"))]
    assert names, "signals to compare"
    for n in names:
        x, y = np.asarray(a[n], dtype=float), np.asarray(b[n], dtype=float)
        assert x.shape == y.shape, f"{what}: {n} shapes {x.shape} vs {y.shape}"
        scale = 1.0 + np.nanmax(np.abs(y)) if y.size else 1.0
        err = np.nanmax(np.abs(x - y)) if x.size else 0.0
        assert err <= tol * scale, f"{what}: {n} differs by {err:.3e} (scale {scale:.3e})"
    assert len(a.events) == len(b.events), f"{what}: {len(a.events)} vs {len(b.events)} events"


@pytest.fixture(scope="module")
def cam():
    return _example("cam_follower")


@pytest.mark.parametrize("factor", [0.9, 1.2])
def test_cam_follower_event_driven_is_the_same_with_and_without_warm_search(cam, factor):
    omega = factor * cam.OMEGA_C
    model = cam.build(omega)
    run = dict(t_end=2 * math.pi / omega, integrator=ms.EventDriven(), output_dt=1e-4)
    warm, cold = ms.simulate(model, **run), ms.simulate(model, warm_search=False, **run)
    _same(warm, cold, f"event-driven at {factor} ω_c")


def test_cam_follower_moreau_jean_is_the_same_with_and_without_warm_search(cam):
    omega = 1.2 * cam.OMEGA_C
    model = cam.build(omega)
    run = dict(t_end=2 * math.pi / omega, integrator=ms.MoreauJean(dt=1e-4), output_dt=1e-3)
    warm, cold = ms.simulate(model, **run), ms.simulate(model, warm_search=False, **run)
    _same(warm, cold, "Moreau-Jean")


def test_gear_rattle_is_the_same_with_and_without_warm_search():
    ex = _example("gear_rattle")
    run = dict(ex.simulation, t_end=0.03)
    warm, cold = ms.simulate(ex.model, **run), ms.simulate(ex.model, warm_search=False, **run)
    _same(warm, cold, "gear rattle")
