"""Batch simulation: many copies of a model -- from different initial states, or variants made by
:meth:`mechsys.Model.with_values` -- run side by side on all cores by the engine, with the
interpreter released (the way MuJoCo's ``rollout`` runs), returned as stacked arrays.

Each case is the same engine run that :func:`mechsys.simulate` makes, so its results equal the
single run's bit for bit, whatever the number of threads.
"""

from __future__ import annotations

import json
import os
from typing import Any, Sequence

import numpy as np

from . import _core
from .errors import ResultsError, SettingsError
from .model import Model
from .results import Results
from .simulate import _settings

__all__ = ["simulate_batch", "BatchResults"]


class BatchResults:
    """The results of :func:`simulate_batch`: ``t`` (time), ``q`` (batch, time, nq), ``u``
    (batch, time, nu), any signal stacked over the cases with ``batch[name]`` (batch, time, ...),
    and the per-case :class:`mechsys.Results` in ``batch.results`` (made on first use). With
    ``on_error="keep"``, ``errors[i]`` is the exception of a failed case (else None) and the
    stacked arrays hold NaN for it."""

    def __init__(self, raws: list, errors: list, make_results):
        self._raws = raws
        self.errors: list[BaseException | None] = errors
        self._make = make_results
        self._results: list[Results | None] | None = None
        ok = next((r for r in raws if r is not None), None)
        self.t = np.array(ok["t"]) if ok is not None else np.zeros(0)
        self.q = self._stack_raw("q")
        self.u = self._stack_raw("u")

    def __len__(self) -> int:
        return len(self._raws)

    def _stack_raw(self, key: str) -> np.ndarray:
        ok = next((r for r in self._raws if r is not None), None)
        if ok is None:
            return np.zeros((len(self._raws), 0, 0))
        shape = np.shape(ok[key])
        return np.stack([r[key] if r is not None else np.full(shape, np.nan) for r in self._raws])

    @property
    def results(self) -> list[Results | None]:
        """Per case, its :class:`mechsys.Results` (None for a failed case)."""
        if self._results is None:
            self._results = [None if r is None else self._make(i, r) for i, r in enumerate(self._raws)]
        return self._results

    def __getitem__(self, name: str | int) -> np.ndarray | Results:
        """A signal stacked over the cases (``batch["q"]``: (cases, samples, ...)), or by an
        integer the one case's :class:`mechsys.Results` (``batch[3]``; negative from the end)."""
        res = self.results
        if isinstance(name, (int, np.integer)) and not isinstance(name, bool):
            i = int(name)
            if not -len(res) <= i < len(res):
                raise ResultsError(f"batch case {i}: the batch has {len(res)} cases (0 .. {len(res) - 1})")
            if res[i] is None:
                raise ResultsError(f"batch case {i} failed: {self.errors[i]}")
            return res[i]
        if not isinstance(name, str):
            raise ResultsError(f"a batch is indexed by a signal name or a case number, got {name!r} "
                               f"({type(name).__name__})")
        ok = next((r for r in res if r is not None), None)
        if ok is None:
            raise KeyError(f"{name}: no case ran")
        shape = np.shape(ok[name])
        return np.stack([r[name] if r is not None else np.full(shape, np.nan) for r in res])

    def names(self) -> list[str]:
        """The names of the recorded signals (as in :meth:`mechsys.Results.names`)."""
        ok = next((r for r in self.results if r is not None), None)
        return ok.names() if ok is not None else []

    def __repr__(self) -> str:
        failed = sum(e is not None for e in self.errors)
        return f"BatchResults({len(self)} cases, {self.t.size} samples, {failed} failed)"


def _cases_from(name: str, value: Any, n_expected: int | None) -> int:
    n = len(value)
    if n_expected is not None and n != n_expected:
        raise SettingsError(f"simulate_batch: {name} has {n} cases, but another argument has {n_expected}")
    if n == 0:
        raise SettingsError(f"simulate_batch: {name} is empty; give at least one case")
    return n


def simulate_batch(
    model: Model,
    t_end: float,
    integrator: Any = None,
    *,
    initial_states: Any = None,
    q0: Any = None,
    u0: Any = None,
    values: Sequence[dict] | None = None,
    output_dt: float | None = None,
    t0: float = 0.0,
    threads: int | None = None,
    sensors: Sequence[str] | None = None,
    stabilization: Any = None,
    on_error: str = "raise",
) -> BatchResults:
    """Simulates many cases of ``model`` from ``t0`` to ``t_end`` on ``threads`` threads (default:
    all cores) in the engine, and stacks their results (:class:`BatchResults`).

    The cases come from any of (all given ones must have the same number of cases):
    ``initial_states`` -- an array (batch, nq + nu) of [q, u] per case; ``q0`` / ``u0`` -- arrays
    (batch, nq) / (batch, nu) or lists of {joint: value} dicts; ``values`` -- a list of parameter
    sets, one dict of dotted paths per case, applied by :meth:`mechsys.Model.with_values`
    (``[{"body.arm.mass": 1.0}, {"body.arm.mass": 1.2}]``). Initial values not given are the
    model's own. ``integrator``, ``output_dt``, ``t0``, ``sensors``, ``stabilization`` are those of
    :func:`mechsys.simulate`, the same for every case.
    ``on_error``: ``"raise"`` (default) raises the first failed case's error (its message starts
    with ``case i:``); ``"keep"`` keeps going and leaves the errors in ``result.errors``.
    A model with Python callbacks (custom forces, time functions) runs its cases one after the
    other in this thread, since callbacks need the interpreter.
    """
    if not isinstance(model, Model):
        raise SettingsError(f"simulate_batch: expected a mechsys.Model, got {type(model).__name__}")
    if on_error not in ("raise", "keep"):
        raise SettingsError(f"on_error: must be 'raise' or 'keep', got {on_error!r}")
    if threads is None:
        threads = os.cpu_count() or 1
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise SettingsError(f"threads: must be a whole number >= 1, got {threads!r}")
    core = model.build()
    # the description and joint table the results carry (`Model.run_metadata`): the caller's
    # model's now, with the build that runs (it may change before results are made); the
    # parameter sets' copies are this function's own, so theirs when their results are made
    shared = model.run_metadata() if values is None else None
    n: int | None = None
    if initial_states is not None:
        states = np.asarray(initial_states, dtype=float)
        if states.ndim != 2 or states.shape[1] != core.nq + core.nu:
            raise SettingsError(f"initial_states: expected an array (batch, nq + nu) = (batch, {core.nq + core.nu}), "
                                f"got shape {states.shape}")
        if q0 is not None or u0 is not None:
            raise SettingsError("simulate_batch: give initial_states or q0/u0, not both")
        n = _cases_from("initial_states", states, n)
        q0, u0 = states[:, :core.nq], states[:, core.nq:]
    if q0 is not None:
        n = _cases_from("q0", q0, n)
    if u0 is not None:
        n = _cases_from("u0", u0, n)
    if values is not None:
        if isinstance(values, dict):
            raise SettingsError("values: expected a list of dicts, one parameter set per case, got one dict")
        n = _cases_from("values", values, n)
    if n is None:
        raise SettingsError("simulate_batch: give the cases as initial_states, q0/u0 or values")

    models = [model] if values is None else []
    if values is not None:
        for i, v in enumerate(values):
            try:
                models.append(model.with_values(v))
            except Exception as e:  # noqa: BLE001 - re-raised naming the case
                raise type(e)(f"case {i}: {e}") from None
    base = _settings(model, t_end, integrator, output_dt, None, None, t0, stabilization)
    chosen = None
    if sensors is not None:
        from .results import record_selection

        base["record"], chosen = record_selection(core, sensors)
    texts = []
    for i in range(n):
        m = models[i] if values is not None else model
        s = dict(base)
        try:
            s["q0"] = m.state_vector(None if q0 is None else q0[i], "q").tolist()
            s["u0"] = m.state_vector(None if u0 is None else u0[i], "u").tolist()
        except Exception as e:  # noqa: BLE001 - re-raised naming the case
            raise type(e)(f"case {i}: {e}") from None
        for which in ("q0", "u0"):
            bad = [k for k, v in enumerate(s[which]) if not np.isfinite(v)]
            if bad:
                raise SettingsError(f"case {i}: {which}[{bad[0]}]: must be finite, got {s[which][bad[0]]}")
        texts.append(json.dumps(s))

    cores = [m.build() for m in models]
    raws: list = [None] * n
    errors: list = [None] * n
    if any(m.callbacks for m in models):
        for i, text in enumerate(texts):
            m = models[i] if values is not None else model
            try:
                raws[i] = _core.simulate(m.build(), text, m.callbacks or None, None)
            except Exception as e:  # noqa: BLE001 - kept per case
                errors[i] = type(e)(f"case {i}: {e}")
    else:
        # in a worker thread, so that Ctrl-C here cancels the engine's cases (each stops at its
        # next sample) instead of waiting for the whole batch
        import threading

        from .simulate import _wait

        prog = _core.Progress()
        out: list = []
        failed: list[BaseException] = []
        done = threading.Event()

        def run():
            try:
                out.extend(_core.simulate_batch(cores, texts, int(threads), prog))
            except BaseException as e:  # noqa: BLE001 - re-raised in the calling thread
                failed.append(e)
            finally:
                done.set()

        worker = threading.Thread(target=run, name="mechsys-simulate-batch")
        worker.start()
        interrupted = _wait(done, prog, 0, False)
        worker.join()
        if interrupted:
            raise KeyboardInterrupt("simulate_batch cancelled")
        if failed:
            raise failed[0]
        for i, (raw, err) in enumerate(out):
            raws[i], errors[i] = raw, err
    if on_error == "raise":
        first = next((e for e in errors if e is not None), None)
        if first is not None:
            raise first

    def make(i: int, raw: dict) -> Results:
        m = models[i] if values is not None else model
        c = cores[i] if values is not None else core
        description, joints = shared if shared is not None else m.run_metadata()
        raw = dict(raw)
        raw.pop("warnings", None)
        attrs = {
            "model": description,
            "settings": texts[i],
            "stats": json.dumps(raw.pop("stats")),
            "events": raw.pop("events_json", "[]"),
            "mechsys_version": _core.__version__,
            "case": i,
        }
        if chosen is not None:
            attrs["sensors"] = json.dumps(list(sensors) if not isinstance(sensors, str) else [sensors])
        res = Results.from_raw(raw, joints, c.body_names[1:], attrs, engine=c, callbacks=m.callbacks or None,
                               keep=chosen)
        return res

    return BatchResults(raws, errors, make)
