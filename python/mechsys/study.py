"""Parameter studies: one model over a grid, a random or a Latin-hypercube sample of named
parameters, run in parallel on local processes (or threads) or on a Dask ``distributed`` cluster.

>>> st = ms.study("examples/quarter_car.toml", {"force.suspension.d": np.linspace(500, 3000, 64)},
...               metrics={"peak": "absmax:body/body/acceleration[y]"})  # doctest: +SKIP
>>> st.to_pandas(); st.save("results/damping.h5"); st.plot("peak")  # doctest: +SKIP

Every case runs the same code on the same inputs wherever it runs, so a parallel study gives the
same floats as a serial one (the reductions of the built-in metrics are order independent:
``math.fsum`` for sums). A case that raises is recorded as failed with its error, and the study
goes on.
"""

from __future__ import annotations

import inspect
import json
import math
import os
import pickle
import time
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from .errors import MechsysError, ResultsError, SettingsError
from .model import Model


class StudyError(MechsysError, ValueError):
    """A parameter study that cannot start: a bad parameter, sample, function or cluster."""


#: Seconds to wait for a Dask scheduler given by its address (and for its first worker).
CONNECT_TIMEOUT = 5.0
#: Study file format version.
FORMAT_VERSION = 1


# ---- values on the command line and dotted overrides ---------------------------------------------
def parse_value(text: str) -> Any:
    """A value as a TOML literal (``2``, ``1.5e3``, ``[0, 0, -9.81]``, ``true``, ``"x"``, an inline
    table); anything else is taken as a bare string (``rk4``)."""
    import tomllib

    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def parse_assignment(text: str, option: str = "--set") -> tuple[str, Any]:
    """``PATH=VALUE`` as (path, parsed value)."""
    path, sep, value = text.partition("=")
    path = path.strip()
    if not sep or not path or not value.strip():
        raise SettingsError(f"{option} {text!r}: expected PATH=VALUE, e.g. force.damper.d=1500")
    return path, parse_value(value.strip())


def apply_values(model: Model, simulation: dict | None, values: Mapping[str, Any]) -> tuple[Model, dict]:
    """``model`` and its simulation table with dotted-path values applied: ``simulation.KEY...``
    paths go to the table (``simulation.t_end``, ``simulation.integrator.rtol``), all others to a
    new model (:meth:`Model.with_values`). Unknown paths are errors naming them."""
    from .modelfile import SIMULATION_KEYS, _check_simulation

    sim = dict(simulation or {})
    model_values = {}
    for path, value in values.items():
        if not isinstance(path, str):
            raise StudyError(f"parameter {path!r}: expected a dotted path (a string)")
        if not path.startswith("simulation."):
            model_values[path] = value
            continue
        parts = path.split(".")[1:]
        if not parts or not all(parts):
            raise SettingsError(f"parameter '{path}': expected simulation.KEY")
        key = parts[0]
        if key not in SIMULATION_KEYS:
            raise SettingsError(f"parameter '{path}': unknown simulation key '{key}'; expected one of {', '.join(SIMULATION_KEYS)}")
        if len(parts) == 1:
            sim[key] = value
            continue
        sim[key] = node = _as_table(sim.get(key), f"simulation.{key}", path)
        for k, part in enumerate(parts[1:-1], start=1):
            node[part] = node = _as_table(node.get(part), f"simulation.{'.'.join(parts[:k + 1])}", path)
        node[parts[-1]] = value
    if model_values:
        model = model.with_values(model_values)
    if any(p.startswith("simulation.") for p in values):
        sim = _check_simulation(sim, model, allow_objects=True)
    return model, sim


def _as_table(value: Any, where: str, path: str) -> dict:
    """A copy of a simulation table, an integrator or solver object as its table, {} for none."""
    from .modelfile import _INTEGRATOR_CLASSES, _SOLVER_CLASSES, _fields

    if value is None:
        return {}
    if isinstance(value, Mapping):
        return dict(value)
    if isinstance(value, str):
        return {"type": value.lower()}
    table = _fields(value, {**_INTEGRATOR_CLASSES, **_SOLVER_CLASSES})
    if table is None:
        raise SettingsError(f"parameter '{path}': {where} is a value ({value!r}), not a table")
    return table


# ---- samples -------------------------------------------------------------------------------------
def _bounds(name: str, spec: Any) -> tuple[float, float]:
    try:
        lo, hi = (float(x) for x in spec)
    except (TypeError, ValueError):
        raise StudyError(f"params['{name}']: a random or Latin-hypercube sample needs bounds (low, high), got {spec!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
        raise StudyError(f"params['{name}']: bounds must be finite with low < high, got ({lo}, {hi})")
    return lo, hi


def latin_hypercube(n: int, d: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` points in the unit cube [0, 1)^d, each of the ``n`` equal strata of every dimension
    holding exactly one point (a random permutation of the strata per dimension, a uniform
    position within each stratum)."""
    out = np.empty((n, d))
    for k in range(d):
        strata = rng.permutation(n)
        out[:, k] = (strata + rng.random(n)) / n
        # (stratum + u) / n may round up to the next stratum's edge for u just below 1
        out[:, k] = np.minimum(out[:, k], np.nextafter((strata + 1) / n, 0.0))
    return out


def make_cases(params: Mapping[str, Any], sample: str = "grid", n: int | None = None, seed: int = 0
               ) -> tuple[list[dict], dict[str, np.ndarray]]:
    """The cases (one {name: value} dict each) and, for a grid, the axis values per parameter.
    ``grid``: every combination of the values given per parameter (the first parameter varies
    slowest); ``random``: ``n`` uniform points within (low, high) per parameter; ``lhs``: a Latin
    hypercube of ``n`` points within the bounds."""
    if not isinstance(params, Mapping) or not params:
        raise StudyError("params: expected a dict of parameter name -> values (grid) or (low, high) bounds")
    names = list(params)
    for name in names:
        if not isinstance(name, str) or not name:
            raise StudyError(f"params: parameter names must be non-empty strings, got {name!r}")
    if sample == "grid":
        if n is not None:
            raise StudyError("n: a grid takes its size from the values of each parameter; n is for random and lhs samples")
        axes = {}
        for name in names:
            spec = params[name]
            vals = list(spec) if isinstance(spec, (list, tuple, np.ndarray, range)) else None
            if not vals:
                raise StudyError(f"params['{name}']: a grid needs a non-empty list of values, got {spec!r}")
            arr = np.asarray(vals)
            if arr.ndim != 1 and arr.dtype != object:
                arr = np.empty(len(vals), dtype=object)
                arr[:] = vals
            if arr.dtype.kind in "fc" and not np.all(np.isfinite(arr)):
                raise StudyError(f"params['{name}']: values must be finite, got {spec!r}")
            axes[name] = arr
        mesh = np.meshgrid(*[np.arange(len(axes[k])) for k in names], indexing="ij")
        idx = np.stack([m.reshape(-1) for m in mesh], axis=1)
        cases = [{k: _plain(axes[k][i]) for k, i in zip(names, row)} for row in idx]
        return cases, axes
    if sample not in ("random", "lhs"):
        raise StudyError(f"sample: expected 'grid', 'random' or 'lhs', got {sample!r}")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise StudyError(f"n: a {sample} sample needs a whole number of cases >= 1, got {n!r}")
    bounds = [_bounds(k, params[k]) for k in names]
    rng = np.random.default_rng(seed)
    unit = rng.random((int(n), len(names))) if sample == "random" else latin_hypercube(int(n), len(names), rng)
    cases = [{k: float(lo + (hi - lo) * u) for k, (lo, hi), u in zip(names, bounds, row)} for row in unit]
    return cases, {}


def _plain(v: Any) -> Any:
    return v.item() if isinstance(v, np.generic) else v


# ---- metrics -------------------------------------------------------------------------------------
REDUCTIONS = ("max", "min", "absmax", "mean", "rms", "std", "ptp", "final", "initial")


def _reduce(kind: str, x: np.ndarray) -> float:
    x = np.asarray(x, dtype=float).reshape(-1)
    if x.size == 0:
        raise ResultsError("no samples to reduce")
    if kind == "max":
        return float(np.max(x))
    if kind == "min":
        return float(np.min(x))
    if kind == "absmax":
        return float(np.max(np.abs(x)))
    if kind == "ptp":
        return float(np.max(x) - np.min(x))
    if kind == "final":
        return float(x[-1])
    if kind == "initial":
        return float(x[0])
    mean = math.fsum(x.tolist()) / x.size
    if kind == "mean":
        return mean
    if kind == "rms":
        return math.sqrt(math.fsum((x * x).tolist()) / x.size)
    d = x - mean
    return math.sqrt(math.fsum((d * d).tolist()) / x.size)  # std


class SignalMetric:
    """A metric ``REDUCTION:SIGNAL`` or ``REDUCTION:SIGNAL[COLUMN]`` (``absmax:body/body/acceleration[y]``):
    one of max, min, absmax, mean, rms, std, ptp, final, initial over a signal's samples
    (a column by name or index; sums are exact, so the value does not depend on where it ran)."""

    def __init__(self, spec: str, name: str | None = None):
        if not isinstance(spec, str) or ":" not in spec:
            raise StudyError(f"metric {name or spec!r}: expected REDUCTION:SIGNAL[COLUMN] "
                             f"(reductions {', '.join(REDUCTIONS)}), got {spec!r}")
        kind, _, signal = spec.partition(":")
        kind, signal = kind.strip(), signal.strip()
        if kind not in REDUCTIONS:
            raise StudyError(f"metric {name or spec!r}: unknown reduction '{kind}'; expected one of {', '.join(REDUCTIONS)}")
        column = None
        if signal.endswith("]") and "[" in signal:
            signal, _, column = signal[:-1].rpartition("[")
        if not signal:
            raise StudyError(f"metric {name or spec!r}: no signal name")
        self.spec, self.kind, self.signal, self.column = spec, kind, signal, column

    def __call__(self, res) -> float:
        x = np.asarray(res[self.signal])
        if self.column is not None:
            if x.ndim != 2:
                raise ResultsError(f"metric '{self.spec}': signal '{self.signal}' has no columns")
            cols = res.columns(self.signal)
            if self.column in cols:
                x = x[:, cols.index(self.column)]
            elif self.column.isdigit() and int(self.column) < x.shape[1]:
                x = x[:, int(self.column)]
            else:
                raise ResultsError(f"metric '{self.spec}': signal '{self.signal}' has no column '{self.column}' "
                                   f"(columns: {', '.join(cols)})")
        elif x.ndim == 2 and x.shape[1] != 1:
            raise ResultsError(f"metric '{self.spec}': signal '{self.signal}' has {x.shape[1]} columns; "
                               f"name one, e.g. {self.signal}[{res.columns(self.signal)[0]}]")
        return _reduce(self.kind, x)

    def __repr__(self) -> str:
        return f"SignalMetric({self.spec!r})"


def _metric_table(metrics: Any) -> Callable | dict:
    if metrics is None:
        raise StudyError("metrics: give a function results -> {name: number} or a dict name -> function or "
                         "'REDUCTION:SIGNAL[COLUMN]'")
    if callable(metrics) and not isinstance(metrics, Mapping):
        return metrics
    if isinstance(metrics, (list, tuple)):
        metrics = {m: m for m in metrics}
    if not isinstance(metrics, Mapping) or not metrics:
        raise StudyError(f"metrics: expected a function, a dict or a list of 'REDUCTION:SIGNAL', got {metrics!r}")
    out = {}
    for name, m in metrics.items():
        if isinstance(m, str):
            out[str(name)] = SignalMetric(m, str(name))
        elif callable(m):
            out[str(name)] = m
        else:
            raise StudyError(f"metrics['{name}']: expected a function or 'REDUCTION:SIGNAL', got {type(m).__name__}")
    return out


# ---- one case ------------------------------------------------------------------------------------
class _Spec:
    """What every case needs, sent once to each worker: the model (or its build function), the
    simulation settings, the run and the metric functions."""

    def __init__(self, build, model, simulation, run, metrics):
        self.build, self.model, self.simulation, self.run, self.metrics = build, model, simulation, run, metrics

    def model_for(self, case: dict) -> tuple[Model, dict]:
        if self.model is not None:
            return apply_values(self.model, self.simulation, case)
        sim_values = {k: v for k, v in case.items() if k.startswith("simulation.")}
        kwargs = {k: v for k, v in case.items() if not k.startswith("simulation.")}
        model = self.build(**kwargs)
        if not isinstance(model, Model):
            raise StudyError(f"build returned {type(model).__name__}, not a mechsys.Model")
        if sim_values:
            _, sim = apply_values(model, self.simulation, sim_values)
            return model, sim
        return model, self.simulation

    def evaluate(self, case: dict) -> dict[str, float]:
        model, sim = self.model_for(case)
        if self.run is not None:
            res = self.run(model)
        else:
            from .modelfile import simulation_kwargs
            from .simulate import simulate

            res = simulate(model, progress=False, **simulation_kwargs(sim))
        if isinstance(self.metrics, dict):
            values = {name: f(res) for name, f in self.metrics.items()}
        else:
            values = self.metrics(res)
            if not isinstance(values, Mapping):
                raise StudyError(f"metrics returned {type(values).__name__}, not a dict name -> number")
        out = {}
        for name, v in values.items():
            try:
                x = float(v)
            except (TypeError, ValueError):
                raise StudyError(f"metric '{name}': expected a number, got {v!r}") from None
            if not math.isfinite(x):
                raise StudyError(f"metric '{name}' is {x} (not finite)")
            out[str(name)] = x
        return out


def _run_case(spec: _Spec, index: int, case: dict) -> tuple[int, str, dict, str, float]:
    start = time.perf_counter()
    try:
        values = spec.evaluate(case)
        return index, "ok", values, "", time.perf_counter() - start
    except Exception as e:  # noqa: BLE001 - a failed case is recorded, the study goes on
        msg = " ".join(str(e).split()) or "(no message)"
        return index, "failed", {}, f"{type(e).__name__}: {msg}", time.perf_counter() - start


_WORKER_SPEC: _Spec | None = None


def _init_worker(blob: bytes) -> None:
    global _WORKER_SPEC
    import warnings

    warnings.simplefilter("ignore")  # a case's warnings would repeat once per worker
    _WORKER_SPEC = pickle.loads(blob)


def _run_in_worker(index: int, case: dict):
    assert _WORKER_SPEC is not None
    return _run_case(_WORKER_SPEC, index, case)


# ---- the study -----------------------------------------------------------------------------------
def study(
    build: Callable[..., Model] | Model | str | Path,
    params: Mapping[str, Any],
    run: Callable | None = None,
    metrics: Any = None,
    *,
    sample: str = "grid",
    n: int | None = None,
    seed: int = 0,
    settings: Mapping[str, Any] | None = None,
    client: Any = None,
    workers: int | None = None,
    pool: str = "processes",
    progress: bool = True,
    store: str | Path | None = None,
    connect_timeout: float = CONNECT_TIMEOUT,
) -> "Study":
    """Runs one model over a sample of parameter values and collects metrics per case.

    ``build``: a function ``build(**case) -> Model``; or a :class:`Model` or a model file path,
    whose parameters are then dotted paths into the description (``force.damper.d``,
    ``body.arm.mass``, ``simulation.t_end``, see :meth:`Model.with_values`). ``params``: name ->
    a list of values (``sample="grid"``, every combination) or (low, high) bounds
    (``"random"`` or ``"lhs"``, a Latin hypercube; ``n`` cases from ``seed``). ``run(model) ->
    Results`` (default: :func:`mechsys.simulate` with ``settings``, a ``[simulation]``-style dict
    laid over a model file's own). ``metrics``: ``results -> {name: number}``, or a dict name ->
    function or ``"REDUCTION:SIGNAL[COLUMN]"`` (see :class:`SignalMetric`).

    Where: ``client`` a ``distributed.Client`` or a scheduler address (``"tcp://host:8786"``);
    else ``workers`` local processes (default: every core; ``pool="threads"`` runs the engine on
    threads with the GIL released instead, for models without Python callbacks); ``workers=1`` runs
    in this process. The functions must pickle (module-level functions) for processes.
    ``progress``: one progress bar over the cases. ``store``: a path to save the study to
    (``.h5``, or ``.zarr`` with zarr installed). ``connect_timeout``: seconds to reach a scheduler
    given by address and to see its first worker. A case that raises is recorded (``status``
    ``failed``, its ``error``) and the study goes on."""
    model = None
    simulation: dict = {}
    if isinstance(build, (str, Path)):
        from .modelfile import load_model

        model, simulation = load_model(build)
        build_fn = None
    elif isinstance(build, Model):
        model, build_fn = build, None
    elif callable(build):
        build_fn = build
    else:
        raise StudyError(f"build: expected a function (**case) -> Model, a mechsys.Model or a model file, got {type(build).__name__}")
    if settings is not None:
        if not isinstance(settings, Mapping):
            raise StudyError(f"settings: expected a dict like a [simulation] table, got {type(settings).__name__}")
        simulation = {**simulation, **dict(settings)}
    if run is not None and not callable(run):
        raise StudyError(f"run: expected a function model -> Results, got {type(run).__name__}")
    metric_fns = _metric_table(metrics)
    cases, axes = make_cases(params, sample, n, seed)
    spec = _Spec(build_fn, model, simulation, run, metric_fns)
    _check_parameters(spec, list(params), cases[0])
    if run is None and "simulation.t_end" not in params and simulation.get("t_end") is None:
        raise StudyError("settings: no t_end to simulate to; give settings={'t_end': ...}, a model file with "
                         "[simulation] t_end, a 'simulation.t_end' parameter or a run function")
    if pool not in ("processes", "threads"):
        raise StudyError(f"pool: expected 'processes' or 'threads', got {pool!r}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1):
        raise StudyError(f"workers: expected a whole number >= 1, got {workers!r}")

    start = time.perf_counter()
    count = min(int(workers) if workers is not None else (os.cpu_count() or 1), len(cases))
    blob = _pickled_spec(spec) if client is None and pool == "processes" and count > 1 else b""
    if client is not None:
        client = connect(client, float(connect_timeout))
    bar = _bar(len(cases), progress)
    try:
        if client is not None:
            outcomes = _run_dask(spec, cases, client, bar, float(connect_timeout))
            where = "dask"
        else:
            if count <= 1:
                outcomes = []
                for i, c in enumerate(cases):
                    outcomes.append(_run_case(spec, i, c))
                    bar.update(1)
                where = "serial"
            elif pool == "threads":
                outcomes = _run_threads(spec, cases, count, bar)
                where = f"{count} threads"
            else:
                outcomes = _run_processes(blob, cases, count, bar)
                where = f"{count} processes"
    finally:
        bar.close()
    wall = time.perf_counter() - start
    st = Study.from_outcomes(params, sample, cases, axes, outcomes, {"ran_on": where, "wall": wall, "seed": seed})
    if store is not None:
        st.save(store)
    return st


def _check_parameters(spec: _Spec, names: list[str], first: dict) -> None:
    """Errors naming a parameter the model (or build function) does not have, before any case runs."""
    if spec.model is not None:
        try:
            apply_values(spec.model, spec.simulation, first)
        except MechsysError as e:
            msg = str(e)
            # a path the model does not have stops the study; a value the engine refuses fails
            # only its case (the first case's value is no better than the others')
            if msg.startswith("parameter '") or "not a key of the model description" in msg or "unknown key" in msg:
                raise
        return
    try:
        sig = inspect.signature(spec.build)
    except (TypeError, ValueError):
        return
    if any(p.kind is p.VAR_KEYWORD for p in sig.parameters.values()):
        return
    takes = [p.name for p in sig.parameters.values() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
    for name in names:
        if not name.startswith("simulation.") and name not in takes:
            raise StudyError(f"params['{name}']: not a parameter of {getattr(spec.build, '__name__', 'build')}"
                             f"({', '.join(takes)})")


def _bar(total: int, progress: bool):
    from tqdm import tqdm

    return tqdm(total=total, desc="study", unit="case", disable=not progress, leave=False)


def _pickled_spec(spec: _Spec) -> bytes:
    for what, obj in (("build", spec.build), ("run", spec.run), ("model", spec.model)):
        try:
            pickle.dumps(obj)
        except MechsysError as e:
            raise type(e)(f"{e}; or run the study with pool='threads' or workers=1 (a Dask cluster takes such "
                          "functions by value)") from None
        except Exception as e:  # noqa: BLE001
            name = getattr(obj, "__qualname__", type(obj).__name__)
            raise StudyError(f"{what}: '{name}' cannot be sent to worker processes ({type(e).__name__}: {e}); define "
                             "it at module level (not a lambda, a nested function or in __main__ of an interactive "
                             "session), or pass workers=1") from None
    items = spec.metrics.items() if isinstance(spec.metrics, dict) else [("", spec.metrics)]
    for name, f in items:
        try:
            pickle.dumps(f)
        except Exception as e:  # noqa: BLE001
            fname = getattr(f, "__qualname__", type(f).__name__)
            where = f"metrics['{name}']" if name else "metrics"
            raise StudyError(f"{where}: '{fname}' cannot be sent to worker processes ({type(e).__name__}: {e}); define "
                             "it at module level (not a lambda or a nested function), or pass workers=1") from None
    return pickle.dumps(spec)


def _collect(ex, futures: dict, bar, broken=None) -> list:
    """Outcomes of the submitted cases as they finish (one bar step each); ``broken`` maps an
    exception of a dead worker to a failed outcome. On Ctrl-C (or any error here) the cases not
    started are dropped, not waited for (each future cancelled here: the executor's own
    cancelling is skipped once it is collected)."""
    from concurrent.futures import as_completed

    outcomes: list = []
    try:
        for fut in as_completed(futures):
            try:
                outcomes.append(fut.result())
            except Exception as e:  # noqa: BLE001 - only a dead worker is turned into an outcome
                if broken is None or not broken[0](e):
                    raise
                outcomes.append(broken[1](futures[fut], e))
            bar.update(1)
    except BaseException:
        for fut in futures:
            fut.cancel()
        ex.shutdown(wait=False, cancel_futures=True)
        raise
    ex.shutdown(wait=True)
    return outcomes


def _run_processes(blob: bytes, cases: list[dict], count: int, bar) -> list:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    ctx = multiprocessing.get_context("spawn")  # no fork of a process with engine threads
    ex = ProcessPoolExecutor(max_workers=count, mp_context=ctx, initializer=_init_worker, initargs=(blob,))
    futures: dict = {}
    try:
        futures = {ex.submit(_run_in_worker, i, c): i for i, c in enumerate(cases)}
    except BaseException:
        ex.shutdown(wait=False, cancel_futures=True)
        raise
    dead = (lambda e: isinstance(e, BrokenProcessPool),
            lambda i, e: (i, "failed", {}, (f"BrokenProcessPool: a worker process died ({e}); a script that starts a "
                                            "study on processes must do so under if __name__ == '__main__':"), math.nan))
    return _collect(ex, futures, bar, dead)


def _run_threads(spec: _Spec, cases: list[dict], count: int, bar) -> list:
    from concurrent.futures import ThreadPoolExecutor

    ex = ThreadPoolExecutor(max_workers=count)
    futures: dict = {}
    try:
        futures = {ex.submit(_run_case, spec, i, c): i for i, c in enumerate(cases)}
    except BaseException:
        ex.shutdown(wait=False, cancel_futures=True)
        raise
    return _collect(ex, futures, bar)


def connect(client: Any, timeout: float = CONNECT_TIMEOUT):
    """A ``distributed.Client`` for a client or a scheduler address (StudyError naming the address
    when it cannot be reached within ``timeout`` seconds, or has no worker)."""
    try:
        import distributed
    except ImportError:
        raise StudyError("client: a Dask cluster needs the 'distributed' package (pip install 'mechsys[study]')") from None
    if isinstance(client, distributed.Client):
        return client, False
    if not isinstance(client, str):
        raise StudyError(f"client: expected a distributed.Client or a scheduler address such as 'tcp://host:8786', "
                         f"got {type(client).__name__}")
    addr = client if "://" in client else f"tcp://{client}"
    _probe(client, addr, timeout)
    import threading

    made: list = []

    def make():
        try:
            made.append(distributed.Client(addr, timeout=f"{timeout}s", set_as_default=False))
        except BaseException as e:  # noqa: BLE001 - handed to the waiting thread
            made.append(e)

    # the client's own timeout does not cover every stage of its handshake: a hard limit here
    maker = threading.Thread(target=make, name="mechsys-dask-connect", daemon=True)
    maker.start()
    maker.join(timeout + 5.0)
    if not made:
        raise StudyError(f"client: cannot reach the Dask scheduler at '{client}': no answer within {timeout + 5.0:g} s")
    try:
        if isinstance(made[0], BaseException):
            raise made[0]
        c = made[0]
    except (OSError, TimeoutError) as e:
        raise StudyError(f"client: cannot reach the Dask scheduler at '{client}' within {timeout:g} s "
                         f"({type(e).__name__}: {' '.join(str(e).split())})") from None
    except Exception as e:  # noqa: BLE001 - something answered there, but not a Dask scheduler
        raise StudyError(f"client: cannot reach the Dask scheduler at '{client}': what answers there is not a "
                         f"Dask scheduler ({type(e).__name__}: {' '.join(str(e).split())[:200]})") from None
    return c, True


def _probe(client: str, addr: str, timeout: float) -> None:
    """A refused or unroutable TCP address fails at once here (the Dask client would retry it
    until its timeout); other schemes are left to the client."""
    import socket
    from urllib.parse import urlsplit

    try:
        parts = urlsplit(addr)
        host, port = parts.hostname, parts.port
    except ValueError as e:
        raise StudyError(f"client: '{client}' is not a scheduler address ({e}); expected tcp://host:port") from None
    if parts.scheme != "tcp":
        return
    if not host or port is None:
        raise StudyError(f"client: '{client}' is not a scheduler address; expected tcp://host:port")
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            # a Dask scheduler greets first (the 8-byte length of its handshake message); the Dask
            # client would wait for that greeting without end
            sock.settimeout(timeout)
            head = b""
            deadline = time.monotonic() + timeout
            while len(head) < 8 and time.monotonic() < deadline:
                chunk = sock.recv(8 - len(head))
                if not chunk:
                    break
                head += chunk
    except socket.timeout:
        head = None
    except OSError as e:
        raise StudyError(f"client: cannot reach the Dask scheduler at '{client}' ({type(e).__name__}: "
                         f"{e.strerror or e})") from None
    if not head or len(head) < 8:
        raise StudyError(f"client: cannot reach the Dask scheduler at '{client}': something accepts connections "
                         f"there but sends no Dask greeting within {timeout:g} s")
    if int.from_bytes(head, "little") > 1 << 24:
        raise StudyError(f"client: cannot reach the Dask scheduler at '{client}': what answers there is not a "
                         "Dask scheduler")


def _run_dask(spec: _Spec, cases: list[dict], connected: tuple, bar, timeout: float = CONNECT_TIMEOUT) -> list:
    from distributed import as_completed

    c, owned = connected
    try:
        try:
            c.wait_for_workers(1, timeout=timeout)
        except (TimeoutError, OSError) as e:
            raise StudyError(f"client: the Dask scheduler at '{c.scheduler.address}' has no worker "
                             f"after {timeout:g} s ({type(e).__name__})") from None
        import uuid

        run_id = uuid.uuid4().hex
        [shared] = c.scatter([spec], broadcast=True, hash=False)
        futures = [c.submit(_run_case, shared, i, case, pure=False, key=f"mechsys-case-{i}-{run_id}")
                   for i, case in enumerate(cases)]
        index = {f.key: i for i, f in enumerate(futures)}
        outcomes = []
        try:
            for fut in as_completed(futures):
                try:
                    outcomes.append(fut.result())
                except Exception as e:  # noqa: BLE001 - a lost worker: the case is recorded as failed
                    outcomes.append((index[fut.key], "failed", {}, f"{type(e).__name__}: {' '.join(str(e).split())}",
                                     math.nan))
                bar.update(1)
        except BaseException:
            c.cancel(futures)  # Ctrl-C: the cluster stops working for this study
            raise
        return outcomes
    finally:
        if owned:
            c.close()


# ---- results of a study --------------------------------------------------------------------------
class Study:
    """The cases of a parameter study with their metrics, ``status`` (``ok`` or ``failed``) and
    ``error`` (type and message of a failed case's exception, else empty)."""

    def __init__(self, names: list[str], sample: str, values: dict[str, np.ndarray], axes: dict[str, np.ndarray],
                 metrics: dict[str, np.ndarray], status: np.ndarray, error: np.ndarray, wall: np.ndarray, attrs: dict):
        self.names, self.sample, self.values, self.axes = names, sample, values, axes
        self.metrics, self.status, self.error, self.wall, self.attrs = metrics, status, error, wall, attrs

    @classmethod
    def from_outcomes(cls, params, sample, cases, axes, outcomes, attrs) -> "Study":
        ncase = len(cases)
        outcomes = sorted(outcomes, key=lambda o: o[0])
        names: list[str] = []
        for o in outcomes:
            for k in o[2]:
                if k not in names:
                    names.append(k)
        metrics = {k: np.full(ncase, np.nan) for k in names}
        status = np.array(["failed"] * ncase, dtype=object)
        error = np.array(["not run"] * ncase, dtype=object)
        wall = np.full(ncase, np.nan)
        for i, st, vals, err, w in outcomes:
            missing = [k for k in names if k not in vals]
            if st == "ok" and missing:
                st, err = "failed", f"StudyError: metrics returned no {', '.join(repr(m) for m in missing)}"
            status[i], error[i], wall[i] = st, err, w
            if st == "ok":
                for k in names:
                    metrics[k][i] = vals[k]
        values = {k: _column([c[k] for c in cases]) for k in params}
        return cls(list(params), sample, values, {k: np.asarray(v) for k, v in axes.items()}, metrics, status, error,
                   wall, dict(attrs))

    def __len__(self) -> int:
        return len(self.status)

    @property
    def failed(self) -> list[int]:
        """Indices of the failed cases."""
        return [i for i, s in enumerate(self.status) if s != "ok"]

    def __repr__(self) -> str:
        return (f"Study({len(self)} cases ({self.sample}) over {', '.join(self.names)}; metrics "
                f"{', '.join(self.metrics) or '(none)'}; {len(self.failed)} failed)")

    def to_pandas(self):
        """A DataFrame, one row per case (index ``case``): parameters, metrics, status, error."""
        import pandas as pd

        data: dict[str, Any] = {k: self.values[k] for k in self.names}
        data.update(self.metrics)
        data["status"] = list(self.status)
        data["error"] = list(self.error)
        return pd.DataFrame(data, index=pd.RangeIndex(len(self), name="case"))

    def to_xarray(self):
        """An xarray Dataset: for a grid one dimension per parameter (its values as the
        coordinate), else a ``case`` dimension with the parameters as coordinates along it."""
        import xarray as xr

        data = {k: v for k, v in self.metrics.items()}
        data["status"] = np.asarray(self.status, dtype=str)
        data["error"] = np.asarray(self.error, dtype=str)
        if self.sample == "grid" and self.axes:
            shape = tuple(len(self.axes[k]) for k in self.names)
            return xr.Dataset({k: (self.names, np.asarray(v).reshape(shape)) for k, v in data.items()},
                              coords={k: self.axes[k] for k in self.names}, attrs={"sample": self.sample})
        coords = {k: ("case", self.values[k]) for k in self.names}
        coords["case"] = np.arange(len(self))
        return xr.Dataset({k: ("case", v) for k, v in data.items()}, coords=coords, attrs={"sample": self.sample})

    # ---- files ---------------------------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Writes the study to one HDF5 file (``.h5``/``.hdf5``, atomically, with a CRC-32 per
        dataset and a completeness marker as for results) or to a Zarr store (``.zarr``, needs the
        ``zarr`` package)."""
        path = Path(path)
        if path.suffix.lower() == ".zarr":
            try:
                import zarr  # noqa: F401
            except ImportError:
                raise ResultsError(f"'{path}': a Zarr store needs the 'zarr' package; save to .h5 instead") from None
            self.to_xarray().to_zarr(path, mode="w")
            return path
        import h5py

        from .files import atomic_path
        from .results import _crc32

        with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
            f.attrs["format"] = "mechsys-study"
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["sample"] = self.sample
            f.attrs["params"] = json.dumps(self.names)
            f.attrs["metrics"] = json.dumps(list(self.metrics))
            f.attrs["attrs"] = json.dumps(self.attrs, default=str)
            f.attrs["axes"] = json.dumps({k: _jsonable(v) for k, v in self.axes.items()})
            f.attrs["values"] = json.dumps({k: _jsonable(v) for k, v in self.values.items()})
            table = np.stack([self.metrics[k] for k in self.metrics], axis=1) if self.metrics else np.zeros((len(self), 0))
            for name, arr in (("metrics", table), ("wall", self.wall)):
                ds = f.create_dataset(name, data=np.ascontiguousarray(arr, dtype=float))
                ds.attrs["crc32"] = _crc32(np.ascontiguousarray(arr, dtype=float))
            f.attrs["status"] = json.dumps(list(self.status))
            f.attrs["error"] = json.dumps(list(self.error))
            f.attrs["complete"] = True
        return path

    @classmethod
    def load(cls, path: str | Path) -> "Study":
        """Reads a study written by :meth:`save` (HDF5), checking its marker and checksums."""
        import h5py

        from .results import _crc32

        path = Path(path)
        if not path.exists():
            raise ResultsError(f"study file '{path}' does not exist")
        try:
            with h5py.File(path, "r") as f:
                if f.attrs.get("format") != "mechsys-study":
                    raise ResultsError(f"'{path}' is not a mechsys study file (no 'format' attribute)")
                if int(f.attrs.get("format_version", 0)) != FORMAT_VERSION:
                    raise ResultsError(f"'{path}': study format version {f.attrs.get('format_version')} is not "
                                       f"{FORMAT_VERSION}")
                if not bool(f.attrs.get("complete", False)):
                    raise ResultsError(f"'{path}': incomplete study file (its writing stopped part-way)")
                arrays = {}
                for name in ("metrics", "wall"):
                    a = np.asarray(f[name][()])
                    if int(f[name].attrs.get("crc32", -1)) != _crc32(a):
                        raise ResultsError(f"'{path}': dataset '{name}' is corrupt (checksum mismatch)")
                    arrays[name] = a
                meta = {k: json.loads(f.attrs[k]) for k in ("params", "metrics", "attrs", "axes", "values", "status", "error")}
                sample = str(f.attrs["sample"])
        except ResultsError:
            raise
        except (OSError, KeyError, ValueError, TypeError) as e:
            raise ResultsError(f"'{path}': unreadable study file ({type(e).__name__}: {e})") from None
        metrics = {k: arrays["metrics"][:, j].copy() for j, k in enumerate(meta["metrics"])}
        return cls(meta["params"], sample, {k: _column(v) for k, v in meta["values"].items()},
                   {k: _column(v) for k, v in meta["axes"].items()}, metrics, np.array(meta["status"], dtype=object),
                   np.array(meta["error"], dtype=object), arrays["wall"], meta["attrs"])

    # ---- plots ---------------------------------------------------------------------------------
    def plot(self, metric: str, x: str | None = None, y: str | None = None, out: str | Path | None = None, ax=None):
        """A metric over one parameter (a line; failed cases left out) or two (an image of a grid
        with a colour bar, or coloured points of a random sample). ``x``/``y`` default to the first
        (two) parameters. Returns the matplotlib figure; ``out`` also writes it."""
        import matplotlib

        if out is not None and ax is None:
            matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        if metric not in self.metrics:
            raise StudyError(f"plot: unknown metric '{metric}'; the study has {', '.join(self.metrics) or '(none)'}")
        x = x or self.names[0]
        for which, name in (("x", x), ("y", y)):
            if name is not None and name not in self.names:
                raise StudyError(f"plot: {which}='{name}' is not a parameter of the study ({', '.join(self.names)})")
        if y is None and len(self.names) > 1 and self.sample == "grid":
            others = [k for k in self.names if k != x]
            y = others[0] if len(others) == 1 else None
            if len(others) > 1:
                raise StudyError(f"plot: the grid has {len(self.names)} parameters; choose x and y")
        fig = ax.figure if ax is not None else plt.figure(figsize=(6.4, 4.4))
        ax = ax or fig.add_subplot(111)
        val = self.metrics[metric]
        ok = np.asarray(self.status == "ok", dtype=bool)
        if y is None:
            xs = np.asarray(self.values[x], dtype=float)
            order = np.argsort(xs[ok], kind="stable")
            ax.plot(xs[ok][order], val[ok][order], "o-", ms=3)
            if (~ok).any():
                ax.plot(xs[~ok], np.full((~ok).sum(), np.nanmin(val) if ok.any() else 0.0), "rx", label="failed")
                ax.legend()
            ax.set_ylabel(metric)
        elif self.sample == "grid":
            da = self.to_xarray()[metric].transpose(y, x)
            im = ax.pcolormesh(np.asarray(da[x], dtype=float), np.asarray(da[y], dtype=float), da.values, shading="auto")
            fig.colorbar(im, ax=ax, label=metric)
            ax.set_ylabel(y)
        else:
            sc = ax.scatter(np.asarray(self.values[x], dtype=float)[ok], np.asarray(self.values[y], dtype=float)[ok],
                            c=val[ok], s=18)
            fig.colorbar(sc, ax=ax, label=metric)
            ax.set_ylabel(y)
        ax.set_xlabel(x)
        ax.set_title(f"{metric} ({self.sample}, {len(self)} cases, {len(self.failed)} failed)", fontsize=10)
        ax.grid(True, alpha=0.3)
        if out is not None:
            from .files import write_atomically

            out = Path(out)
            write_atomically(out, lambda tmp: fig.savefig(tmp, format=out.suffix.lstrip(".") or "png", dpi=120))
        return fig


def _column(values: Sequence) -> np.ndarray:
    try:
        arr = np.asarray(values)
        if arr.ndim == 1:
            return arr
    except (ValueError, TypeError):
        pass
    arr = np.empty(len(values), dtype=object)
    arr[:] = list(values)
    return arr


def _jsonable(v: np.ndarray) -> list:
    return [x.tolist() if isinstance(x, np.ndarray) else _plain(x) for x in v]


def load(path: str | Path) -> Study:
    """Reads a study file (see :meth:`Study.save`)."""
    return Study.load(path)


__all__ = ["study", "Study", "StudyError", "SignalMetric", "make_cases", "latin_hypercube", "apply_values",
           "parse_value", "parse_assignment", "connect", "load"]
