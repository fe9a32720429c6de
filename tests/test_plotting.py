"""Plots of results: one subplot per signal, labelled components, units on the y axes, PNG/SVG output."""

from __future__ import annotations

import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import ResultsError, SettingsError
from mechsys.plotting import component_labels, plot


@pytest.fixture(scope="module", autouse=True)
def _matplotlib_loaded():
    """Import matplotlib once per module so that its start-up cost is not charged to one test."""
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.figure  # noqa: F401


@pytest.fixture(scope="module")
def synthetic() -> ms.Results:
    """Hand-made results (no engine involved) with known values."""
    t = np.linspace(0.0, 1.0, 51)
    signals = {
        "t": t,
        "joint/j/q": np.sin(t),
        "body/b/position": np.column_stack([t, 2 * t, 3 * t]),
        "body/b/orientation": np.column_stack([np.cos(t / 2), 0 * t, 0 * t, np.sin(t / 2)]),
        "joint/s/q": np.column_stack([t, t]),
        "energy/total": np.ones_like(t),
    }
    units = {
        "t": "s",
        "joint/j/q": "rad",
        "body/b/position": "m",
        "body/b/orientation": "1",
        "joint/s/q": "rad",
        "energy/total": "J",
    }
    return ms.Results(signals, units, {"model": '{"name": "synthetic"}'})


@pytest.fixture(scope="module")
def simulated() -> ms.Results:
    m = ms.Model("pendulum", gravity=(0.0, -9.81, 0.0))
    rod = m.add_body("rod", mass=1.0, inertia=[1e-4, 0.0833, 0.0833], com=(0.5, 0.0, 0.0))
    m.add_joint(ms.joints.Revolute("hinge", parent=m.ground, child=rod, axis=(0.0, 0.0, 1.0)))
    return ms.simulate(m, t_end=0.2, integrator=ms.RK4(dt=1e-3), q0={"hinge": 0.3})


def test_one_subplot_per_signal_with_units(synthetic):
    fig = plot(synthetic, ["joint/j/q", "body/b/position", "energy/total"])
    axes = fig.get_axes()
    assert len(axes) == 3
    assert [ax.get_title() for ax in axes] == ["joint/j/q", "body/b/position", "energy/total"]
    assert [ax.get_ylabel() for ax in axes] == ["q [rad]", "position [m]", "total [J]"]
    assert axes[-1].get_xlabel() == "t [s]"
    assert fig._suptitle is not None and fig._suptitle.get_text() == "synthetic"
    # data are plotted against t, unchanged
    line = axes[0].get_lines()[0]
    np.testing.assert_array_equal(line.get_xdata(), synthetic.t)
    np.testing.assert_array_equal(line.get_ydata(), synthetic["joint/j/q"])


def test_vector_components_are_labelled(synthetic):
    fig = plot(synthetic, ["body/b/position", "body/b/orientation", "joint/s/q"], title="components")
    pos, ori, two = fig.get_axes()
    assert [ln.get_label() for ln in pos.get_lines()] == ["x", "y", "z"]
    assert [ln.get_label() for ln in ori.get_lines()] == ["w", "x", "y", "z"]
    assert [ln.get_label() for ln in two.get_lines()] == ["[0]", "[1]"]
    np.testing.assert_array_equal(pos.get_lines()[2].get_ydata(), 3 * synthetic.t)
    assert [tx.get_text() for tx in ori.get_legend().get_texts()] == ["w", "x", "y", "z"]
    assert fig._suptitle.get_text() == "components"


def test_component_labels():
    assert component_labels("body/b/velocity", "m/s", 3) == ["x", "y", "z"]
    assert component_labels("joint/ball/q", "1 (quaternion)", 4) == ["w", "x", "y", "z"]
    assert component_labels("joint/plane/q", "m, m, rad", 3) == ["[0]", "[1]", "[2]"]
    assert component_labels("q", "mixed", 3) == ["[0]", "[1]", "[2]"]
    assert component_labels("joint/free/q", "m, 1 (quaternion)", 7) == [f"[{i}]" for i in range(7)]


def test_writes_png(simulated, tmp_path):
    out = tmp_path / "sub" / "plot.png"
    fig = plot(simulated, ["joint/hinge/q", "body/rod/position"], out=out)
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > 5000
    assert len(fig.get_axes()) == 2


def test_writes_svg(simulated, tmp_path):
    out = tmp_path / "plot.svg"
    ms.plot(simulated, "energy/total", out=out)  # the package-level delegate, one name as a string
    text = out.read_text()
    assert "<svg" in text
    assert "energy/total" in text and "t [s]" in text


def test_unknown_signal_is_named(synthetic):
    with pytest.raises(ResultsError) as e:
        plot(synthetic, ["joint/j/q", "joint/k/q", "energy/totl"])
    msg = str(e.value)
    assert "unknown signals 'joint/k/q', 'energy/totl'" in msg
    assert "energy/total" in msg  # the available names are listed


def test_bad_arguments(synthetic, tmp_path):
    with pytest.raises(SettingsError, match="no signals"):
        plot(synthetic, [])
    with pytest.raises(SettingsError, match=r"'\.jpg'"):
        plot(synthetic, ["joint/j/q"], out=tmp_path / "x.jpg")
    assert not (tmp_path / "x.jpg").exists()
    with pytest.raises(SettingsError, match="signal names must be strings"):
        plot(synthetic, [3])


def test_signal_with_wrong_length(tmp_path):
    res = ms.Results({"t": np.arange(5.0), "x": np.arange(3.0)}, {"t": "s", "x": "m"})
    with pytest.raises(ResultsError, match=r"signal 'x' has shape \(3,\)"):
        plot(res, ["x"])
