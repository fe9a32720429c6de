"""``mechsys batch``: many runs of a model file from a table of initial states and/or parameter
sets, on all cores (see :func:`mechsys.simulate_batch`), saved as stacked arrays in one ``.npz``."""

from __future__ import annotations

import json
import time
from pathlib import Path

import click


def _error(message: str):
    from .cli import CliError

    return CliError(message)


def _load_states(path: Path):
    import numpy as np

    if not path.is_file():
        raise _error(f"--states {path}: no such file")
    try:
        if path.suffix == ".npy":
            return np.load(path, allow_pickle=False)
        return np.loadtxt(path, delimiter="," if path.suffix == ".csv" else None, ndmin=2)
    except (OSError, ValueError) as e:
        raise _error(f"--states {path}: cannot read an array of states ({e})") from None


@click.command("batch")
@click.argument("model_file", metavar="MODEL", type=click.Path(path_type=Path, dir_okay=False))
@click.option("--states", "states_file", type=click.Path(path_type=Path, dir_okay=False),
              help="Initial states, one case per row [q, u] (.npy, .csv or whitespace-separated text).")
@click.option("--values", "values_file", type=click.Path(path_type=Path, dir_okay=False),
              help="Parameter sets: a JSON list with one {dotted.path: value} object per case.")
@click.option("--t-end", type=float, help="End time (s); overrides simulation.t_end.")
@click.option("--dt", type=float, help="Step of rk4/radau5/moreau_jean (s); alone it selects rk4.")
@click.option("--integrator", type=click.Choice(["rk4", "dopri5", "radau5", "moreau_jean"], case_sensitive=False),
              help="Integration scheme.")
@click.option("--rtol", type=float, help="Relative tolerance of dopri5 and adaptive radau5.")
@click.option("--atol", type=float, help="Absolute tolerance of dopri5 and adaptive radau5.")
@click.option("--output-dt", type=float, help="Sampling interval of the results (s).")
@click.option("--threads", type=int, help="Threads [default: every core].")
@click.option("--sensors", "sensors", multiple=True, metavar="PATTERN[,PATTERN...]",
              help="Signals to stack besides t, q and u (names or patterns such as 'joint/*/q').")
@click.option("--keep-going", is_flag=True, help="Go on past failed cases (their rows are NaN, their errors listed).")
@click.option("--out", "out", type=click.Path(path_type=Path, dir_okay=False),
              help="Output .npz [default: results/<model name>_batch.npz].")
@click.option("-q", "--quiet", is_flag=True, help="Print nothing on success.")
def batch_cmd(model_file: Path, states_file: Path | None, values_file: Path | None, t_end, dt, integrator, rtol, atol,
              output_dt, threads, sensors, keep_going, out, quiet) -> None:
    """Simulate many cases of a model file (.toml or .py) on all cores and save t, q, u (and the
    --sensors signals) stacked as arrays (case, time, ...) in one .npz file.

    A .py model file is executed as Python code: run only files you trust."""
    import numpy as np

    from . import simulate_batch
    from .cli import _safe_name, _split_signals
    from .files import check_outputs, write_atomically
    from .modelfile import load_model, simulation_kwargs

    if states_file is None and values_file is None:
        raise _error("give the cases with --states FILE and/or --values FILE")
    states = _load_states(states_file) if states_file is not None else None
    if states is not None and states.ndim != 2:
        raise _error(f"--states {states_file}: expected one row [q, u] per case (a 2-d array), got shape {states.shape}")
    values = None
    if values_file is not None:
        try:
            values = json.loads(Path(values_file).read_text())
        except (OSError, ValueError) as e:
            raise _error(f"--values {values_file}: cannot read a JSON list of parameter sets ({e})") from None
        if not isinstance(values, list) or not all(isinstance(v, dict) for v in values):
            raise _error(f"--values {values_file}: expected a JSON list of objects, one per case")
    model, defaults = load_model(model_file)
    kwargs = simulation_kwargs(defaults, t_end=t_end, output_dt=output_dt, integrator=integrator, dt=dt, rtol=rtol,
                               atol=atol)
    kwargs.pop("q0", None)
    kwargs.pop("u0", None)
    for key in ("sensors", "on_singular", "max_steps", "max_wall"):
        kwargs.pop(key, None)
    chosen = _split_signals(sensors)
    out_path = out if out is not None else Path("results") / f"{_safe_name(model.name)}_batch.npz"
    out_path = check_outputs({"model file": model_file}, {"--out": out_path})["--out"]
    start = time.perf_counter()
    res = simulate_batch(model, initial_states=states, values=values, threads=threads,
                         sensors=chosen or None,
                         on_error="keep" if keep_going else "raise", **kwargs)
    wall = time.perf_counter() - start
    arrays = {"t": res.t, "q": res.q, "u": res.u}
    # every recorded signal the --sensors asked for (patterns resolved by the selection)
    for name in res.names() if chosen else []:
        if name != "t":
            arrays["signal:" + name] = res[name]
    def save(tmp: Path) -> None:
        with open(tmp, "wb") as f:  # a file object: np.savez would append .npz to the temporary name
            np.savez(f, **arrays)

    write_atomically(out_path, save)
    failed = [i for i, e in enumerate(res.errors) if e is not None]
    for i in failed:
        click.echo(f"failed: {res.errors[i]}", err=True)
    if quiet:
        return
    click.echo(f"{len(res)} cases ({len(failed)} failed) of {model.name}, {res.t.size} samples each, "
               f"on {threads or 'all'} threads in {wall:.3g} s; wrote {out_path} "
               f"(t, q {res.q.shape}, u {res.u.shape}" + "".join(f", {k}" for k in arrays if k.startswith("signal:")) + ")")
