"""``simulate``: runs the step loop in Rust (GIL released) and returns :class:`Results`."""

from __future__ import annotations

import json
import threading
import time
from typing import Any, Sequence

import numpy as np

from . import _core
from .errors import SettingsError
from .integrators import DOPRI5, RK4, MoreauJean, Radau5
from .model import Model
from .results import Results


def _settings(model: Model, t_end, integrator, output_dt, q0, u0, t0, stabilization=None, on_singular="continue",
              max_steps=None, max_wall=None) -> dict:
    if integrator is None:
        integrator = DOPRI5()
    if not hasattr(integrator, "describe"):
        raise SettingsError("integrator: expected mechsys.RK4, DOPRI5, Radau5, MoreauJean or EventDriven, "
                            f"got {type(integrator).__name__}")
    try:
        t_end = float(t_end)
        t0 = float(t0)
    except (TypeError, ValueError):
        raise SettingsError(f"t_end and t0 must be numbers, got {t_end!r}, {t0!r}") from None
    if not (np.isfinite(t0) and np.isfinite(t_end) and t_end > t0):
        raise SettingsError(f"t_end: must be finite and > t0 = {t0}, got {t_end}")
    step = getattr(integrator, "dt", None)
    if step is not None and not (isinstance(step, (int, float)) and np.isfinite(step) and step > 0):
        raise SettingsError(f"integrator.dt: must be > 0, got {step}")
    if isinstance(integrator, Radau5) and integrator.rtol is not None:
        r = integrator.rtol
        # checked here too: 0 is how the engine spells "fixed step" (it could not say which was
        # meant), and the value is shown as given (the engine's JSON reading may round it)
        if isinstance(r, bool) or not isinstance(r, (int, float)) or not 1e-14 <= r < 1:
            raise SettingsError(f"integrator.rtol: must be in [1e-14, 1) for adaptive steps (below 1e-14 double "
                                f"precision cannot meet it; 1 and above control nothing), got {r!r}")
    if output_dt is None:
        if isinstance(integrator, RK4) or (isinstance(integrator, Radau5) and integrator.dt is not None):
            output_dt = integrator.dt
        elif isinstance(integrator, MoreauJean):
            # samples fall on steps: the whole multiple of dt nearest to 1/1000 of the span
            output_dt = max(1, round((t_end - t0) / 1000.0 / integrator.dt)) * integrator.dt
        else:
            output_dt = (t_end - t0) / 1000.0 if t_end > t0 else 1.0
    try:
        output_dt = float(output_dt)
    except (TypeError, ValueError):
        raise SettingsError(f"output_dt: must be a number, got {output_dt!r}") from None
    if not (np.isfinite(output_dt) and output_dt > 0):
        raise SettingsError(f"output_dt: must be > 0, got {output_dt}")
    if not (np.isfinite(t_end) and np.isfinite(t0) and t_end > t0):
        raise SettingsError(f"t_end: must be finite and > t0 = {t0}, got {t_end}")
    if on_singular not in ("continue", "stop"):
        raise SettingsError(f"on_singular: must be 'continue' or 'stop', got {on_singular!r}")
    if max_steps is not None and not (isinstance(max_steps, (int, np.integer)) and not isinstance(max_steps, bool)
                                      and max_steps >= 1):
        raise SettingsError(f"max_steps: must be a whole number >= 1, got {max_steps!r}")
    if max_wall is not None:
        try:
            max_wall = float(max_wall)
        except (TypeError, ValueError):
            raise SettingsError(f"max_wall: must be a number of seconds > 0, got {max_wall!r}") from None
        if not (np.isfinite(max_wall) and max_wall > 0):
            raise SettingsError(f"max_wall: must be a number of seconds > 0, got {max_wall!r}")
    qv, uv = model.state_vector(q0, "q"), model.state_vector(u0, "u")
    for which, vec in (("q0", qv), ("u0", uv)):
        bad = np.nonzero(~np.isfinite(np.asarray(vec, dtype=float)))[0]
        if bad.size:
            k = int(bad[0])
            key = "iq" if which == "q0" else "iu"
            width = "nq" if which == "q0" else "nu"
            joint = next((j["name"] for j in model.joint_info() if j[key] <= k < j[key] + j[width]), "?")
            raise SettingsError(f"{which}[{k}]: joint '{joint}' gets a value that is not finite ({vec[k]}); give numbers")
    return {
        "t0": t0,
        "t_end": t_end,
        "output_dt": float(output_dt),
        "integrator": integrator.describe(),
        "q0": qv.tolist(),
        "u0": uv.tolist(),
        "stabilization": _stabilization(stabilization),
        "on_singular": on_singular,
        "max_steps": None if max_steps is None else int(max_steps),
        "max_wall": max_wall,
    }


def simulate(
    model: Model,
    t_end: float,
    integrator: Any = None,
    output_dt: float | None = None,
    q0: Any = None,
    u0: Any = None,
    t0: float = 0.0,
    progress: bool | None = None,
    keep: Sequence[str] = (),
    stabilization: Any = None,
    on_singular: str = "continue",
    max_steps: int | None = None,
    max_wall: float | None = None,
    sensors: Sequence[str] | None = None,
    warm_search: bool = True,
) -> Results:
    """Simulates ``model`` from ``t0`` to ``t_end``.

    ``integrator``: :class:`mechsys.RK4`, :class:`mechsys.DOPRI5` (default) or
    :class:`mechsys.Radau5` for smooth models; :class:`mechsys.MoreauJean` (time-stepping) or
    :class:`mechsys.EventDriven` for models with contacts (their events in ``res.events``).
    ``output_dt``: sampling interval of the results (default: the step of RK4 and fixed Radau5, the
    whole multiple of the step nearest to 1/1000 of the span for MoreauJean, else 1/1000 of the
    span). ``q0``/``u0``: full vectors or ``{joint name: value}`` dicts
    (the joints' own q0/u0 elsewhere). ``progress``: show a progress bar (default: only when
    the run takes longer than about a second and stderr is a terminal). ``keep``: joints whose
    q0 and u0 stay as given when a constrained model is assembled to a consistent start (the
    others move by minimum-norm corrections). ``stabilization``: constraint drift control,
    ``"projection"`` (default), ``"none"`` or :class:`mechsys.constraints.Baumgarte`.
    ``on_singular``: at a singular configuration (the constraint equations lose rank: a dead
    point, a parallelogram linkage passing its flat position) ``"continue"`` (default) goes on
    with minimum-norm multipliers and notes the passage as a warning with its time and
    constraint; ``"stop"`` raises a SolverError there. ``max_steps`` (accepted steps of RK4,
    DOPRI5, Radau5) and ``max_wall`` (seconds, any scheme) are budgets: the run stops with a
    SolverError saying which was spent and at what time. An RK4 run whose energy grows
    geometrically (a step above the stability limit) stops with a SolverError naming the stiffest
    spring and the step that would be stable.
    ``sensors``: record only these signals — names or patterns (``"joint/*/q"``,
    ``"marker/arm/tip/*"``, ``"energy/total"``); the engine then skips the bodies, accelerations,
    constraint and force values nothing asked for (default None: everything). A pattern that
    matches no signal of the model is a SettingsError naming it.
    ``warm_search``: contact searches of planar curved contours start from the last evaluation's
    contact points while the bodies have provably not moved far enough to change them (the same
    points as a full search, see docs/contours.md); ``False`` searches from scratch every time.
    """
    if not isinstance(model, Model):
        raise SettingsError(f"simulate: expected a mechsys.Model, got {type(model).__name__}")
    core = model.build()
    # taken with the build that runs (the model could change before the results are made)
    description, joints = model.run_metadata()
    if core.nc:
        _warn_redundant(model, q0, t0)
    if keep:
        # assemble with the named joints held at their given q0, u0 (the engine's own start
        # projection then finds the state consistent and leaves it)
        from .analysis import assemble

        q0, u0 = assemble(model, q0, u0, float(t0), keep=keep)
    settings = _settings(model, t_end, integrator, output_dt, q0, u0, t0, stabilization, on_singular, max_steps, max_wall)
    settings["warm_search"] = bool(warm_search)
    chosen = None
    if sensors is not None:
        from .results import record_selection

        settings["record"], chosen = record_selection(core, sensors)
    text = json.dumps(settings)
    callbacks = model.callbacks or None
    prog = _core.Progress()
    n_expected = int(np.floor((settings["t_end"] - settings["t0"]) / settings["output_dt"] * (1 + 1e-12) + 1e-9)) + 1

    raw: dict = {}
    error: list[BaseException] = []

    def run():
        try:
            raw.update(_core.simulate(core, text, callbacks, prog))
        except BaseException as e:  # noqa: BLE001 - re-raised in the calling thread
            error.append(e)

    if callbacks:
        # callbacks need the interpreter; running in this thread keeps tracebacks simple
        run()
    else:
        interrupted = _wait(_engine_thread(run), prog, n_expected, progress)
        if interrupted and (error or "cancelled" not in raw):
            # stopped otherwise (an error, or it ended on its own just then): the interrupt wins
            raise KeyboardInterrupt
    if error:
        raise error[0]
    import warnings

    for note in raw.pop("warnings", []):
        warnings.warn(f"model '{model.name}': {note}", UserWarning, stacklevel=2)
    attrs = {
        "model": description,
        "settings": text,
        "stats": json.dumps(raw.pop("stats")),
        "events": raw.pop("events_json", "[]"),
        "mechsys_version": _core.__version__,
    }
    body_names = core.body_names[1:]
    cancelled = raw.pop("cancelled", None)
    if chosen is not None:
        attrs["sensors"] = json.dumps(list(sensors) if not isinstance(sensors, str) else [sensors])
    res = Results.from_raw(raw, joints, body_names, attrs, engine=core, callbacks=callbacks, keep=chosen)
    if cancelled is not None:
        # Ctrl-C: the samples before it are kept on the interrupt (`except KeyboardInterrupt as e:
        # e.results`)
        interrupt = KeyboardInterrupt(f"{cancelled}; the results so far are in .results")
        interrupt.results = res
        raise interrupt
    return res


_pool: tuple | None = None  # (pid, executor, lock): the kept engine thread of this process


def _engine_thread(run) -> threading.Event:
    """Starts ``run`` on an engine thread; returns the event set once it has ended.

    One thread is kept between runs: starting a thread for each costs a few tenths of a
    millisecond, much of it the new thread's allocator faulting in the pages of the result arrays
    afresh. A run while that thread is busy (runs from several Python threads) gets a thread of
    its own. Neither is a daemon: the interpreter never ends while the engine still runs in it (a
    daemon thread stopped at exit inside the engine aborts the process); the executor's thread is
    joined at exit. The executor is made anew in a forked child, which does not inherit threads.

    The kept thread is free again before the event is set, and the caller waits on the event
    alone: waiting on the executor's future as well cost a second hand-over between the threads
    (about a tenth of a millisecond per run on a 2-core VM, a tenth of a short run).
    """
    global _pool
    import os

    done = threading.Event()
    if _pool is None or _pool[0] != os.getpid():
        from concurrent.futures import ThreadPoolExecutor

        _pool = (os.getpid(), ThreadPoolExecutor(max_workers=1, thread_name_prefix="mechsys-simulate"), threading.Lock())
    _, pool, lock = _pool
    if lock.acquire(blocking=False):

        def job():
            try:
                run()
            finally:
                lock.release()
                done.set()

        try:
            pool.submit(job)
        except RuntimeError:  # the executor was shut down (interpreter exit): a thread of its own
            lock.release()
        else:
            return done

    def own():
        try:
            run()
        finally:
            done.set()

    threading.Thread(target=own, name="mechsys-simulate").start()
    return done


def _stabilization(value) -> dict:
    from .constraints import stabilization

    return stabilization(value)


def _warn_redundant(model: Model, q0, t0) -> None:
    """Warns once per model when constraint equations are dependent at the start (e.g. a planar
    loop closed in 3-D); the engine gives them zero multipliers, which is usually what one wants."""
    import warnings

    from .mechanisms import mobility

    key = (model._built[0] if model._built else None, "redundancy-warned")
    if getattr(model, "_warned", None) == key:
        return
    try:
        mob = mobility(model, model.state_vector(q0, "q"), float(t0))
    except Exception:  # noqa: BLE001 - the simulation itself reports bad states properly
        return
    model._warned = key
    if mob["redundant"]:
        names = ", ".join(f"{n}[{k}]" for n, k in mob["redundant"])
        warnings.warn(
            f"model '{model.name}': {len(mob['redundant'])} redundant constraint equation(s) at t0: {names}; "
            "they share the load with the rows they repeat (minimum-norm multipliers)",
            stacklevel=3,
        )


def _wait(done: threading.Event, prog, n_expected: int, progress: bool | None) -> bool:
    """Waits for the simulation thread to set ``done``, showing a bar after ~1 s; returns whether
    Ctrl-C cancelled the run. Ctrl-C cancels: the engine stops at its next sample and returns the
    samples so far, raised by the caller on a KeyboardInterrupt (further Ctrl-C meanwhile only
    repeat the request). The wait is on an Event, not on ``Thread.join``, whose state an
    interrupt can leave claiming the thread ended."""
    import sys

    start = time.perf_counter()
    bar = None
    try:
        while not done.wait(0.05):
            if bar is None:
                show = progress if progress is not None else sys.stderr.isatty()
                if show and time.perf_counter() - start > 1.0:
                    from tqdm import tqdm

                    bar = tqdm(total=n_expected, unit="sample", desc="simulating", leave=False)
            if bar is not None:
                bar.n = prog.samples
                bar.refresh()
    except KeyboardInterrupt:
        prog.cancel()
        while True:
            try:
                if done.wait(0.05):
                    break
            except KeyboardInterrupt:
                prog.cancel()
        return True
    finally:
        if bar is not None:
            bar.n = prog.samples
            bar.close()


__all__ = ["simulate"]
