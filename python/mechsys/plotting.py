"""Plots of simulation results: one subplot per signal against time.

Vector signals get one line per component, labelled ``x, y, z`` (three-component vectors),
``w, x, y, z`` (quaternions: ``body/<b>/orientation`` and spherical-joint coordinates) or by index.
Figures are built without pyplot's global state when saved or when there is no display (the Agg
canvas), so plotting from scripts, tests and the command line never needs a GUI.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Iterable, Sequence

import numpy as np

from .errors import ResultsError, SettingsError

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from .results import Results

#: Output formats :func:`plot` writes, by file extension.
FORMATS: tuple[str, ...] = (".png", ".svg", ".pdf")


def _headless() -> bool:
    """True when no display is available (Linux without X11/Wayland)."""
    if sys.platform.startswith("linux"):
        return not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return False


def component_labels(name: str, unit: str, count: int) -> list[str]:
    """Legend labels for the ``count`` components of a vector signal."""
    if count == 4 and (name.endswith("/orientation") or "quaternion" in unit):
        return ["w", "x", "y", "z"]
    if count == 3 and "," not in unit and unit != "mixed":
        return ["x", "y", "z"]
    return [f"[{i}]" for i in range(count)]


def _signal_list(signals: str | Iterable[str]) -> list[str]:
    if isinstance(signals, str):
        return [signals]
    names = list(signals)
    for n in names:
        if not isinstance(n, str):
            raise SettingsError(f"plot: signal names must be strings, got {type(n).__name__} {n!r}")
    return names


def _check_names(results: "Results", names: Sequence[str]) -> None:
    unknown = [n for n in names if n not in results]
    if not unknown:
        return
    available = [n for n in results.names() if n != "t"]
    shown = ", ".join(available[:30]) + (", ..." if len(available) > 30 else "")
    which = ", ".join(f"'{n}'" for n in unknown)
    raise ResultsError(f"unknown signal{'s' if len(unknown) > 1 else ''} {which}; available: {shown}")


def plot(
    results: "Results",
    signals: str | Iterable[str],
    out: str | Path | None = None,
    title: str | None = None,
    *,
    figsize: tuple[float, float] | None = None,
    dpi: int = 150,
) -> "Figure":
    """Plots ``signals`` of ``results`` against time, one subplot per signal.

    ``signals``: a name or a list of names (``res.names()`` lists them). Each subplot's y-axis is
    labelled with the signal's unit; vector signals show one labelled line per component.
    ``out``: if given, the figure is saved there, the format chosen by the extension (``.png``,
    ``.svg`` or ``.pdf``). ``title``: figure title (default: the model name). ``figsize`` in
    inches (default 8 wide, about 2.2 per subplot high); ``dpi`` for PNG output.

    Returns the matplotlib :class:`~matplotlib.figure.Figure`. An unknown signal raises
    :class:`mechsys.ResultsError` naming it.

    >>> fig = plot(res, ["joint/hinge/q", "energy/total"], out="pendulum.png")  # doctest: +SKIP
    """
    names = _signal_list(signals)
    if not names:
        raise SettingsError("plot: no signals given")
    _check_names(results, names)
    path = Path(out) if out is not None else None
    if path is not None and path.suffix.lower() not in FORMATS:
        shown = f"'{path.suffix}'" if path.suffix else "no extension"
        raise SettingsError(f"plot: cannot write {path} ({shown}); use one of {', '.join(FORMATS)}")

    t = np.asarray(results.t, dtype=float)
    series = []
    for n in names:
        a = np.asarray(results[n])
        if a.ndim == 0 or a.shape[0] != t.shape[0]:
            raise ResultsError(f"signal '{n}' has shape {a.shape}, not one row per sample ({t.shape[0]})")
        series.append(a.reshape(t.shape[0], -1))

    size = figsize or (8.0, 0.8 + 2.2 * len(names))
    if path is not None or _headless():
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=size)
        FigureCanvasAgg(fig)
    else:
        import matplotlib.pyplot as plt

        fig = plt.figure(figsize=size)

    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    for ax, n, a in zip(axes, names, series):
        unit = results.unit(n)
        if a.shape[1] == 1:
            ax.plot(t, a[:, 0], lw=1.2)
        else:
            named = getattr(results, "_columns", {}).get(n, ([],))[0]
            labels = named if len(named) == a.shape[1] else component_labels(n, unit, a.shape[1])
            for label, col in zip(labels, a.T):
                ax.plot(t, col, lw=1.2, label=label)
            ax.legend(loc="upper right", fontsize="small", ncols=min(a.shape[1], 7), framealpha=0.7)
        ax.set_title(n, fontsize="medium")
        short = n.rsplit("/", 1)[-1]
        ax.set_ylabel(f"{short} [{unit}]" if unit else short)
        ax.grid(True, alpha=0.3)
        # absolute tick labels: a conserved energy would otherwise read as an offset axis of noise
        # (review newcomer.md, finding 13)
        try:
            ax.ticklabel_format(axis="y", useOffset=False)
        except AttributeError:  # a formatter without offsets
            pass
    axes[-1].set_xlabel("t [s]")
    if len(t):
        axes[-1].set_xlim(t[0], t[-1] if t[-1] > t[0] else t[0] + 1.0)

    if title is None:
        try:
            title = results.model.get("name")
        except Exception:  # noqa: BLE001 - a results file without a readable model description
            title = None
    if title:
        fig.suptitle(title, y=1.0 - 0.12 / size[1], va="top")
    # fixed margins in inches: a layout engine would lay out (and draw) the figure twice per save
    width, height = size
    top, bottom, gap = 0.45 + (0.3 if title else 0.0), 0.55, 0.55
    n = len(names)
    axes_height = max((height - top - bottom - (n - 1) * gap) / n, 0.2)
    fig.subplots_adjust(
        left=min(1.0 / width, 0.3),
        right=1.0 - min(0.25 / width, 0.1),
        bottom=min(bottom / height, 0.3),
        top=max(1.0 - top / height, 0.6),
        hspace=gap / axes_height,
    )

    if path is not None:
        from .files import write_atomically

        write_atomically(path, lambda tmp: fig.savefig(tmp, dpi=dpi, format=path.suffix.lower()[1:]))
    return fig


__all__ = ["plot", "component_labels", "FORMATS"]
