"""``mechsys study``: a parameter study of a model file from the command line (see
:func:`mechsys.study.study`)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import click


def _error(message: str):
    from .cli import CliError

    return CliError(message)


def parse_param(text: str, sample: str) -> tuple[str, Any]:
    """``PATH=LO:HI:N`` (a grid of N evenly spaced values, both ends included), ``PATH=[a, b, ...]``
    (the values given) or ``PATH=LO:HI`` (bounds of a random or Latin-hypercube sample)."""
    import numpy as np

    from .study import parse_value

    path, sep, spec = text.partition("=")
    path, spec = path.strip(), spec.strip()
    if not sep or not path or not spec:
        raise _error(f"--param {text!r}: expected PATH=LO:HI:N, PATH=[v1,v2,...] or PATH=LO:HI")
    if spec.startswith("["):
        values = parse_value(spec)
        if not isinstance(values, list) or not values:
            raise _error(f"--param {path}: expected a non-empty list of values, got {spec!r}")
        if sample != "grid":
            raise _error(f"--param {path}: a list of values is a grid; a {sample} sample takes bounds LO:HI")
        return path, values
    parts = spec.split(":")
    try:
        nums = [float(p) for p in parts[:2]]
        count = int(parts[2]) if len(parts) == 3 else None
    except ValueError:
        raise _error(f"--param {path}: LO and HI must be numbers and N a whole number, got {spec!r}") from None
    if len(parts) not in (2, 3) or not all(np.isfinite(nums)) or nums[1] <= nums[0]:
        raise _error(f"--param {path}: expected LO:HI:N or LO:HI with finite LO < HI, got {spec!r}")
    if sample == "grid":
        if count is None or count < 1:
            raise _error(f"--param {path}: a grid needs LO:HI:N with N >= 1, got {spec!r}")
        return path, np.linspace(nums[0], nums[1], count).tolist()
    if count is not None:
        raise _error(f"--param {path}: a {sample} sample takes bounds LO:HI (the number of cases is --n), got {spec!r}")
    return path, (nums[0], nums[1])


def parse_metric(text: str) -> tuple[str, str]:
    """``NAME=REDUCTION:SIGNAL[COLUMN]`` or ``REDUCTION:SIGNAL[COLUMN]`` (named by itself)."""
    name, sep, spec = text.partition("=")
    if not sep:
        name, spec = text, text
    name, spec = name.strip(), spec.strip()
    if not name or ":" not in spec:
        raise _error(f"--metric {text!r}: expected [NAME=]REDUCTION:SIGNAL[COLUMN], e.g. "
                     "peak=absmax:body/body/acceleration[y]")
    return name, spec


@click.command("study")
@click.argument("model_file", metavar="MODEL", type=click.Path(path_type=Path, dir_okay=False))
@click.option("--param", "params", multiple=True, required=True, metavar="PATH=SPEC",
              help="A parameter by its dotted path: LO:HI:N (grid), [v1,v2,...] (grid) or LO:HI (random, lhs); repeatable.")
@click.option("--metric", "metrics", multiple=True, required=True, metavar="[NAME=]REDUCTION:SIGNAL[COL]",
              help="A metric per case: max, min, absmax, mean, rms, std, ptp, final or initial of a signal "
                   "(a column by name or index); repeatable.")
@click.option("--sample", type=click.Choice(["grid", "random", "lhs"]), default="grid", show_default=True,
              help="Every combination of the values, or N random / Latin-hypercube points within the bounds.")
@click.option("--n", "n", type=int, help="Number of cases of a random or lhs sample.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of a random or lhs sample.")
@click.option("--set", "set_values", multiple=True, metavar="PATH=VALUE",
              help="A fixed change to the model or simulation (as for mechsys run); repeatable.")
@click.option("--workers", type=int, help="Local worker processes [default: every core]; 1 runs in this process.")
@click.option("--threads", is_flag=True, help="Run the cases on threads (the engine releases the GIL) instead of processes.")
@click.option("--scheduler", metavar="ADDR", help="Run on the Dask scheduler at ADDR (tcp://host:8786).")
@click.option("--out", "out", type=click.Path(path_type=Path, dir_okay=False),
              help="Study file (.h5, or .zarr with zarr installed) [default: results/<model name>-study.h5].")
@click.option("--plot", "plot_out", type=click.Path(path_type=Path, dir_okay=False),
              help="Plot the first metric over the (first two) parameters (.png, .svg or .pdf).")
@click.option("--follow-symlinks", "follow_symlinks", is_flag=True,
              help="Write through an output path that is a symbolic link (refused by default).")
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no summary.")
def study_cmd(model_file: Path, params: tuple[str, ...], metrics: tuple[str, ...], sample: str, n: int | None,
              seed: int, set_values: tuple[str, ...], workers: int | None, threads: bool, scheduler: str | None,
              out: Path | None, plot_out: Path | None, follow_symlinks: bool, quiet: bool) -> None:
    """Run a model file over a grid, random or Latin-hypercube sample of parameters (dotted paths
    as for --set) and save one metric table: e.g.

    mechsys study car.toml --param force.suspension.d=500:3000:64 --metric peak=absmax:body/body/acceleration[y]

    A case that fails is recorded with its error and the study goes on. A .py model file is
    executed as Python code: run only files you trust."""
    from .cli import _safe_name
    from .files import check_outputs
    from .modelfile import load_model
    from .study import apply_values, parse_assignment, study

    model, defaults = load_model(model_file)
    if set_values:
        model, defaults = apply_values(model, defaults, dict(parse_assignment(v) for v in set_values))
    table = dict(parse_param(p, sample) for p in params)
    if len(table) != len(params):
        raise _error("--param: a parameter is given twice")
    metric_table = dict(parse_metric(m) for m in metrics)
    out_path = out if out is not None else Path("results") / f"{_safe_name(model.name)}-study.h5"
    outs = check_outputs({"model file": model_file}, {"--out": out_path, "--plot": plot_out}, follow_symlinks)
    out_path, plot_out = outs["--out"], outs["--plot"]
    start = time.perf_counter()
    st = study(model, table, metrics=metric_table, sample=sample, n=n, seed=seed, settings=defaults,
               client=scheduler, workers=workers, pool="threads" if threads else "processes", progress=not quiet,
               store=out_path)
    wall = time.perf_counter() - start
    if plot_out is not None:
        names = list(table)
        st.plot(next(iter(metric_table)), x=names[0], y=names[1] if len(names) == 2 else None, out=plot_out)
    if quiet:
        return
    click.echo(f"model     {model.name} ({model_file})")
    click.echo(f"cases     {len(st)} ({sample}), {len(st) - len(st.failed)} ok, {len(st.failed)} failed; "
               f"ran on {st.attrs.get('ran_on')}, wall time {wall:.3g} s")
    for i in st.failed[:5]:
        case = ", ".join(f"{k}={st.values[k][i]!r}" for k in st.names)
        click.echo(f"failed    case {i} ({case}): {st.error[i]}")
    if len(st.failed) > 5:
        click.echo(f"failed    ... and {len(st.failed) - 5} more (see the 'error' column)")
    import numpy as np

    for name, v in st.metrics.items():
        if np.isfinite(v).any():
            lo, hi = int(np.nanargmin(v)), int(np.nanargmax(v))

            def at(i):
                return ", ".join(f"{k}={st.values[k][i]:g}" if isinstance(st.values[k][i], (float, int, np.number))
                                 else f"{k}={st.values[k][i]!r}" for k in st.names)

            click.echo(f"metric    {name}: min {v[lo]:.6g} at {at(lo)}; max {v[hi]:.6g} at {at(hi)}")
    click.echo(f"study     {out_path}")
    if plot_out is not None:
        click.echo(f"plot      {plot_out}")
