"""The ``mechsys`` command line: run model files, inspect models and results, plot signals, analyse
linear vibrations.

::

    mechsys run model.toml --t-end 2 --out results.h5 --plot q.png
    mechsys info model.toml
    mechsys import robot.urdf -o robot.toml     (or a MuJoCo model.xml)
    mechsys signals results.h5
    mechsys plot results.h5 joint/hinge/q energy/total --out q.svg
    mechsys view results.h5 --trail bird --out page.html
    mechsys linear model.toml --at equilibrium --frf 0:1 --campbell spin:0:500:51 --whirl x,y

Errors in the input (model files, settings, results files) are printed as one line
``error: <message>`` on stderr with exit status 2.
"""

from __future__ import annotations

import re
import sys
import time
from pathlib import Path
from typing import Any, Sequence

import click

from ._core import __version__
from .errors import MechsysError

#: Exit status for errors in the user's input (the same as click's usage errors).
EXIT_INPUT_ERROR = 2


class CliError(click.ClickException):
    """An input error shown as ``error: <message>`` with exit status 2."""

    exit_code = EXIT_INPUT_ERROR

    def show(self, file: Any = None) -> None:
        click.echo(f"error: {self.format_message()}", err=True)


def _message(e: BaseException) -> str:
    if isinstance(e, OSError) and not isinstance(e, MechsysError) and e.filename is not None:
        reason = e.strerror or str(e)
        return f"{e.filename}: {reason}"
    msg = str(e).strip()
    return " ".join(msg.splitlines()) or type(e).__name__


class _Group(click.Group):
    """A command group that turns mechsys errors and file errors into :class:`CliError`."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except (MechsysError, OSError) as e:
            raise CliError(_message(e)) from e
        except KeyboardInterrupt:
            # Ctrl-C: the run was cancelled cleanly; the shell's convention for SIGINT is 130
            click.echo("interrupted", err=True)
            raise SystemExit(130) from None


CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


@click.group(cls=_Group, context_settings=CONTEXT)
@click.version_option(__version__, "-V", "--version", prog_name="mechsys", message="%(prog)s %(version)s")
def cli() -> None:
    """mechsys: mechanical system dynamics from the command line.

    Model files are TOML (the model description plus an optional [simulation] table) or Python
    (a module-level `model` and an optional `simulation` dict). A .py model file is executed as
    Python code by run, info and linear: run only files you trust.
    """


# ---- helpers -------------------------------------------------------------------------------------


def _layer(c: dict) -> str:
    """", compliant layer k = ... N/m[, d = ... N s/m]" for a contact on a compliant Signorini layer."""
    comp = c.get("compliance", 0.0)
    if not comp:
        return ""
    damp = c.get("damping", 0.0)
    return f", compliant layer k = {1.0 / comp:.3g} N/m" + (f", d = {damp:.3g} N s/m" if damp else "")


def _table(headers: Sequence[str], rows: Sequence[Sequence[Any]], indent: str = "  ") -> str:
    """A plain-text table with left-aligned columns."""
    cells = [[str(h) for h in headers]] + [[str(c) for c in r] for r in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(headers))]
    lines = []
    for k, r in enumerate(cells):
        lines.append(indent + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
        if k == 0:
            lines.append(indent + "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _fmt_vec(v: Sequence[float]) -> str:
    return "(" + ", ".join(f"{x:g}" for x in v) + ")"


def _safe_name(name: str) -> str:
    # a file-name stem: portable characters, at most 100 of them (file systems stop at 255 bytes);
    # a name that had to be changed gets a short hash of itself, so that two models whose names
    # differ only in what was replaced ("a\\b", "a\nb") do not share a results file
    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._")[:100] or "model"
    if stem != name:
        import hashlib

        stem += "-" + hashlib.sha1(name.encode("utf-8", "surrogatepass")).hexdigest()[:8]
    return stem


def _split_signals(values: Sequence[str]) -> list[str]:
    out: list[str] = []
    for v in values:
        out.extend(s for s in (p.strip() for p in v.split(",")) if s)
    return out


def _describe_integrator(settings: dict) -> str:
    integ = dict(settings.get("integrator") or {})
    kind = integ.pop("type", "?")
    parts = []
    for k, v in integ.items():
        if isinstance(v, bool):
            if v:
                parts.append(f"{k}=true")
        elif isinstance(v, (int, float)) and v:
            parts.append(f"{k}={v:g}")
        elif isinstance(v, dict) and "type" in v:  # moreau_jean's contact solver
            parts.append(f"{k}={v['type']}")
    params = ", ".join(parts)
    if kind == "radau5":
        # its two modes read differently: say which one ran
        mode = "adaptive" if integ.get("rtol") else "fixed step"
        keep = ("rtol", "atol", "max_step", "first_step") if mode == "adaptive" else ("dt", "newton_tol")
        return f"radau5 ({', '.join([mode] + [p for p in parts if p.split('=')[0] in keep])})"
    return f"{kind}({params})" if params else str(kind)


def _default_signals(results: Any, joints: list[dict]) -> list[str]:
    names = []
    for j in joints:
        n = f"joint/{j['name']}/q"
        if j["nq"] > 0 and n in results:
            names.append(n)
            break
    if "energy/total" in results:
        names.append("energy/total")
    # the first compliant contact's (or compliant group's) normal force
    force = next((n for n in results.names() if n.startswith("contact/") and n.endswith("/force_n")), None)
    if force is not None:
        names.append(force)
    # a selective recording (--sensors) may hold neither: its first signals then
    return names or [n for n in results.names() if n != "t"][:2]


# ---- commands ------------------------------------------------------------------------------------


@cli.command()
@click.argument("model_file", metavar="MODEL", type=click.Path(path_type=Path, dir_okay=False))
@click.option("--t-end", type=float, help="End time (s); overrides simulation.t_end.")
@click.option("--t0", type=float, help="Start time (s); overrides simulation.t0.")
@click.option("--dt", type=float, help="Step of rk4/radau5/moreau_jean (s); alone it selects rk4; radau5 with --dt takes fixed steps.")
@click.option("--integrator", type=click.Choice(["rk4", "dopri5", "radau5", "moreau_jean", "event_driven"], case_sensitive=False),
              help="Integration scheme (moreau_jean: time-stepping for models with contacts; event_driven: located contact events).")
@click.option("--solver", type=click.Choice(["nsgs", "newton", "apgd", "lemke", "auto"], case_sensitive=False), help="Contact solver of moreau_jean; overrides the model file's.")
@click.option("--rtol", type=float, help="Relative tolerance of dopri5, event_driven and radau5 (radau5 with --rtol: adaptive steps).")
@click.option("--atol", type=float, help="Absolute tolerance of dopri5, event_driven and adaptive radau5.")
@click.option("--output-dt", type=float, help="Sampling interval of the results (s).")
@click.option("--on-singular", "on_singular", type=click.Choice(["continue", "stop"]), default=None,
              help="At a singular configuration (the constraints lose rank): go on with a warning [default] or stop.")
@click.option("--max-steps", "max_steps", type=int, help="Stop after this many accepted steps (rk4, dopri5, radau5).")
@click.option("--max-wall", "max_wall", type=float, help="Stop after this many seconds of wall-clock time.")
@click.option("--sensors", "sensors", multiple=True, metavar="PATTERN[,PATTERN...]",
              help="Record only these signals (names or patterns such as 'joint/*/q', 'marker/arm/tip/*'); repeat or separate by commas [default: everything].")
@click.option("--set", "set_values", multiple=True, metavar="PATH=VALUE",
              help="Change a model or simulation value by its dotted path (body.arm.mass=2, force.damper.d=1500, "
                   "gravity=[0,0,-9.81], simulation.t_end=2); the value is a TOML literal; repeatable.")
@click.option("--out", "out", type=click.Path(path_type=Path, dir_okay=False), help="HDF5 results file [default: results/<model name>.h5].")
@click.option("--plot", "plot_out", type=click.Path(path_type=Path, dir_okay=False), help="Write a plot (.png, .svg or .pdf).")
@click.option(
    "--signals",
    "signals",
    multiple=True,
    metavar="NAME[,NAME...]",
    help="Signals for --plot and --csv; repeat or separate by commas [default plot: first joint's q, energy/total].",
)
@click.option("--csv", "csv_out", type=click.Path(path_type=Path, dir_okay=False), help="Also write signals as CSV (all if no --signals).")
@click.option("--follow-symlinks", "follow_symlinks", is_flag=True,
              help="Write through an output path that is a symbolic link (refused by default).")
@click.option("-q", "--quiet", is_flag=True, help="Print nothing on success.")
def run(
    model_file: Path,
    t_end: float | None,
    t0: float | None,
    dt: float | None,
    integrator: str | None,
    solver: str | None,
    rtol: float | None,
    atol: float | None,
    output_dt: float | None,
    on_singular: str | None,
    max_steps: int | None,
    max_wall: float | None,
    sensors: tuple[str, ...],
    set_values: tuple[str, ...],
    out: Path | None,
    plot_out: Path | None,
    signals: tuple[str, ...],
    csv_out: Path | None,
    follow_symlinks: bool,
    quiet: bool,
) -> None:
    """Simulate a model file (.toml or .py) and save the results to HDF5.

    A .py model file is executed as Python code: run only files you trust."""
    from . import simulate
    from .errors import ResultsError
    from .modelfile import load_model, simulation_kwargs

    model, defaults = load_model(model_file)
    if set_values:
        from .study import apply_values, parse_assignment

        model, defaults = apply_values(model, defaults, dict(parse_assignment(v) for v in set_values))
    kwargs = simulation_kwargs(
        defaults,
        t_end=t_end,
        t0=t0,
        output_dt=output_dt,
        integrator=integrator,
        solver=solver,
        dt=dt,
        rtol=rtol,
        atol=atol,
        sensors=_split_signals(sensors) or None,
    )
    if on_singular is not None:
        kwargs["on_singular"] = on_singular
    if max_steps is not None:
        kwargs["max_steps"] = max_steps
    if max_wall is not None:
        kwargs["max_wall"] = max_wall
    out_path = out if out is not None else Path("results") / f"{_safe_name(model.name)}.h5"
    # a bad output path is found before the run, not after it
    from .files import check_outputs

    outs = check_outputs({"model file": model_file}, {"--out": out_path, "--plot": plot_out, "--csv": csv_out},
                         follow_symlinks)
    out_path, plot_out, csv_out = outs["--out"], outs["--plot"], outs["--csv"]
    start = time.perf_counter()
    import warnings

    try:
        # the run's warnings as `warning:` lines, not Python's with the source line (review
        # newcomer.md, finding 16)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = simulate(model, **kwargs)
        for w in caught:
            click.echo(f"warning: {w.message}", err=True)
    except KeyboardInterrupt as e:
        partial = getattr(e, "results", None)
        if partial is None or not len(partial.t):
            raise
        # Ctrl-C keeps what was computed: the samples up to the stop, marked as interrupted in
        # the file (attribute 'interrupted'), then the shell's exit status for SIGINT
        partial.attrs["interrupted"] = f"cancelled at t = {partial.t[-1]:g} s of {kwargs.get('t_end', '?')} s"
        partial.save(out_path)
        click.echo(f"interrupted at t = {partial.t[-1]:g} s: the {len(partial.t)} samples so far saved to {out_path}", err=True)
        raise SystemExit(130) from None
    wall = time.perf_counter() - start

    try:
        res.save(out_path)
    except OSError as e:
        raise ResultsError(f"cannot write results file {out_path}: {e.strerror or e}") from None

    chosen = _split_signals(signals)
    unknown = [s for s in chosen if s not in res]
    if unknown:
        which = ", ".join(f"'{s}'" for s in unknown)
        raise ResultsError(
            f"unknown signal{'s' if len(unknown) > 1 else ''} {which} (results saved to {out_path}; "
            f"`mechsys signals {out_path}` lists the names)"
        )
    if plot_out is not None:
        from .plotting import plot

        plot(res, chosen or _default_signals(res, model.joint_info()), out=plot_out)
    if csv_out is not None:
        res.to_csv(csv_out, chosen or None)

    if quiet:
        return
    settings, stats = res.settings, res.stats
    t = res.t
    span = f"t = {t[0]:g} .. {t[-1]:g} s" if len(t) else "no samples"
    rows = [
        ("model", f"{model.name} ({model_file}), nq = {model.nq}, nu = {model.nu}"),
        ("simulated", f"{span}, {len(t)} samples, {_describe_integrator(settings)}"),
        (
            "integrator",
            ", ".join(f"{v} {k}" for k, v in stats.items()) if stats else "no statistics",
        ),
        ("wall time", f"{wall:.3g} s"),
        ("results", str(out_path)),
    ]
    if plot_out is not None:
        rows.append(("plot", str(plot_out)))
    if csv_out is not None:
        rows.append(("csv", str(csv_out)))
    width = max(len(k) for k, _ in rows)
    for k, v in rows:
        click.echo(f"{k.ljust(width)}  {v}")


@cli.command("plot")
@click.argument("results_file", metavar="RESULTS.h5", type=click.Path(path_type=Path, dir_okay=False))
@click.argument("signals", metavar="SIGNAL...", nargs=-1, required=True)
@click.option("-o", "--out", type=click.Path(path_type=Path, dir_okay=False), help="Image file (.png, .svg or .pdf) [default: RESULTS.png].")
@click.option("--title", help="Figure title [default: the model name].")
@click.option("--follow-symlinks", "follow_symlinks", is_flag=True,
              help="Write through an output path that is a symbolic link (refused by default).")
def plot_cmd(results_file: Path, signals: tuple[str, ...], out: Path | None, title: str | None,
             follow_symlinks: bool) -> None:
    """Plot signals of a results file against time, one subplot per signal."""
    from .plotting import plot
    from .results import load

    res = load(results_file)
    out_path = out if out is not None else results_file.with_suffix(".png")
    from .files import check_outputs

    out_path = check_outputs({"results file": results_file}, {"--out": out_path}, follow_symlinks)["--out"]
    plot(res, _split_signals(signals), out=out_path, title=title)
    click.echo(f"plot  {out_path}")


@cli.command()
@click.argument("source", metavar="RESULTS.h5|MODEL", type=click.Path(path_type=Path, dir_okay=False))
@click.option("-o", "--out", type=click.Path(path_type=Path, dir_okay=False),
              help="Page to write (.html) [default: RESULTS.html, or MODEL-mode-K.html].")
@click.option("--signals", "signals", multiple=True, metavar="NAME[,NAME...]", help="Signals to plot beside the scene.")
@click.option("--trail", "trails", multiple=True, metavar="BODY[:x,y,z]",
              help="Draw the path of a body point (body frame; default its origin). Repeatable.")
@click.option("--follow", metavar="BODY", help="The body the camera follows at start.")
@click.option("--max-frames", "max_frames", type=int, default=1500, show_default=True,
              help="Frames kept in the page (uniform in time, plus every event).")
@click.option("--mode", "mode", type=int, metavar="K",
              help="MODEL only: animate mode K (from 1) of the linearization (see --at).")
@click.option("--at", "at", type=click.Choice(["q0", "equilibrium"]), default="q0", show_default=True,
              help="With --mode: linearize at the model's q0/u0 or at the static equilibrium found from q0.")
@click.option("--open", "open_browser", is_flag=True, help="Open the page in the web browser.")
@click.option("--follow-symlinks", "follow_symlinks", is_flag=True,
              help="Write through an output path that is a symbolic link (refused by default).")
def view(source: Path, out: Path | None, signals: tuple[str, ...], trails: tuple[str, ...], follow: str | None,
         max_frames: int, mode: int | None, at: str, open_browser: bool, follow_symlinks: bool) -> None:
    """Write a self-contained 3D viewer page (scene, timeline, contact forces, plots) of a results
    file, or of a mode shape of a model file (--mode); it works offline from a file: URL."""
    from . import viewer
    from .files import check_outputs

    if mode is None:
        from .results import load

        if source.suffix.lower() in (".toml", ".py"):
            raise click.UsageError(f"{source} is a model file: run it first (mechsys run), or give --mode K to see a mode shape")
        target = load(source)
        default = source.with_suffix(".html")
    else:
        from . import linear as lin_mod
        from .modelfile import load_model

        model, _ = load_model(source)
        lin = lin_mod.linearize(model, at=at)
        count = len(lin.modes().eigenvalues)
        if not 1 <= mode <= count:
            raise click.BadParameter(f"mode {mode}: the model has modes 1 to {count}", param_hint="--mode")
        target = viewer.mode_results(lin, mode - 1)
        default = source.with_name(f"{source.stem}-mode-{mode}.html")
    out_path = check_outputs({"input file": source}, {"--out": out or default}, follow_symlinks)["--out"]
    page = viewer.to_html(target, out_path, signals=_split_signals(signals) if signals else None, trails=trails,
                          follow=follow, max_frames=max_frames)
    click.echo(f"page  {page}")
    if open_browser:
        import webbrowser

        webbrowser.open(Path(page).resolve().as_uri())


@cli.command()
@click.argument("model_file", metavar="MODEL", type=click.Path(path_type=Path, dir_okay=False))
def info(model_file: Path) -> None:
    """Describe a model file: bodies, joints, force elements, degrees of freedom.

    A .py model file is executed as Python code: run only files you trust."""
    from .modelfile import load_model

    if model_file.suffix.lower() == ".urdf":
        # a robot description is read as it would be imported (fixed base, limits as data)
        from .urdf import load_urdf

        model, sim = load_urdf(model_file).model, {}
    elif model_file.suffix.lower() in _MJCF_SUFFIXES:
        from .mjcf import load_mjcf

        model, sim = load_mjcf(model_file, unsupported="ignore").model, {}
    else:
        model, sim = load_model(model_file)
    core = model.build()
    bodies = model.body_info()
    joints = model.joint_info()
    forces = core.forces()

    click.echo(f"model    {model.name} ({model_file})")
    click.echo(f"gravity  {_fmt_vec(core.gravity)} m/s^2")
    constraints = core.constraints()
    if constraints:
        from .mechanisms import mobility

        mob = mobility(model)
        click.echo(
            f"DOF      {mob['dof']} (nu = {model.nu} minus constraint rank {mob['rank']} of {mob['nc']} equations), nq = {model.nq}"
        )
    else:
        click.echo(f"DOF      {model.nu} (nu), nq = {model.nq}")
    click.echo("")
    click.echo(f"bodies ({len(bodies)}):")
    if bodies:
        rows = [(b["name"], f"{b['mass']:g}", b["parent_joint"]) for b in bodies]
        click.echo(_table(["name", "mass [kg]", "parent joint"], rows))
    click.echo("")
    click.echo(f"joints ({len(joints)}):")
    if joints:
        rows = [
            (j["name"], f"path ({j['curve']})" if "curve" in j else j["type"], f"{j['parent']} -> {j['child']}",
             f"{j['nq']}/{j['nu']}", f"{j['iq']}/{j['iu']}")
            for j in joints
        ]
        click.echo(_table(["name", "type", "parent -> child", "nq/nu", "iq/iu"], rows))
    elastic = core.elastic()
    if elastic:
        click.echo("")
        click.echo(f"elastic bodies ({len(elastic)}):")
        import numpy as np

        rows = []
        for e in elastic:
            desc = next(b for b in model.to_dict()["bodies"] if b["name"] == e["body"])["elastic"]
            k = np.asarray(desc["stiffness"], dtype=float)
            m_ee = np.array([[np.trace(np.asarray(p2).reshape(3, 3)) for p2 in desc["p2"][r * e["ne"]:(r + 1) * e["ne"]]]
                             for r in range(e["ne"])])
            from scipy.linalg import eigh

            f = np.sqrt(np.maximum(eigh(k, m_ee, eigvals_only=True), 0.0)) / (2 * np.pi)
            rows.append((e["body"], str(e["ne"]), f"{e['iq']}/{e['iu']}", str(len(e["nodes"])),
                         f"{f[0]:.4g} .. {f[-1]:.4g}", "yes" if desc.get("geometric") else "no"))
        click.echo(_table(["body", "modes", "iq/iu", "nodes", "frequencies [Hz]", "geometric stiffness"], rows))
    click.echo("")
    click.echo(f"force elements ({len(forces)}):")
    if forces:
        click.echo(_table(["name", "type"], [(n, t) for n, t in forces]))
    if constraints:
        click.echo("")
        click.echo(f"constraints ({len(constraints)}):")
        click.echo(_table(["name", "type", "equations"], [(c["name"], c["type"], str(c["rows"])) for c in constraints]))
        if mob["redundant"]:
            names = ", ".join(f"{n}[{k}]" for n, k in mob["redundant"])
            click.echo(f"warning: {len(mob['redundant'])} redundant equation(s) at q0: {names} (they share the load with the rows they repeat: minimum-norm multipliers)")
    contacts = core.contacts()
    if contacts:
        click.echo("")
        layered = any(c.get("compliance", 0.0) > 0 for c in contacts)
        schemes = "moreau_jean (compliant layers: time-stepping only)" if layered else "moreau_jean or event_driven"
        click.echo(f"contacts ({len(contacts)}; simulate with --integrator {schemes}):")
        rows = [(c["name"], "gap function" if c.get("kind") == "gap" else f"{c['body1']} / {c['body2']}", str(c["points"]),
                 ("planar" if c["tangents"] == 1 else "spatial") + _layer(c))
                for c in contacts]
        click.echo(_table(["name", "bodies", "points", "kind"], rows))
    groups = core.contact_groups() if hasattr(core, "contact_groups") else []
    if groups:
        click.echo("")
        click.echo(f"contact groups ({len(groups)}; pairs found by a broad phase at every step; simulate with --integrator moreau_jean):")
        rows = [(g["name"], str(g["members"]), ", ".join(g["member_kinds"]), str(g["against"]),
                 ", ".join(g["against_kinds"]) or "-", ("planar" if g["planar"] else "spatial") + _layer(g)) for g in groups]
        click.echo(_table(["name", "members", "member contours", "against", "against contours", "kind"], rows))
    if sim:
        click.echo("")
        click.echo("simulation defaults:")
        for k, v in sim.items():
            if k == "integrator" and hasattr(v, "describe"):  # an integrator object (Python model files)
                v = v.describe()
            if isinstance(v, dict) and "type" in v:
                v = _describe_integrator({"integrator": v})
            click.echo(f"  {k} = {v}")


_MJCF_SUFFIXES = (".xml", ".mjcf")


@cli.command("import")
@click.argument("urdf_file", metavar="ROBOT.urdf|MODEL.xml", type=click.Path(path_type=Path, dir_okay=False))
@click.option("-o", "--out", type=click.Path(path_type=Path, dir_okay=False), help="TOML model file [default: ROBOT.toml].")
@click.option("--root", type=click.Choice(["ground", "free"]), default="ground", show_default=True,
              help="URDF: fixed base (the root link is the ground) or a free-floating base.")
@click.option("--limits", type=click.Choice(["data", "stops"]), default="data", show_default=True,
              help="Joint limits as data only, or also as gap-contact stops.")
@click.option("--package-dir", "package_dirs", multiple=True, type=click.Path(path_type=Path, file_okay=False),
              help="URDF: folder searched for package:// meshes (repeatable).")
def import_cmd(urdf_file: Path, out: Path | None, root: str, limits: str, package_dirs: tuple[Path, ...]) -> None:
    """Import a URDF robot description or a MuJoCo MJCF model (.xml, .mjcf; compiled by the
    mujoco package) as a TOML model file that run and info accept.

    Links (bodies) become bodies, joints joints, URDF mimic joints couplers. Collision geometry is
    not written (attach it from Python with mechsys.load_urdf(...).contours or load_mjcf)."""
    from ._import import limits_header
    from .tomlwrite import dumps

    if urdf_file.suffix.lower() in _MJCF_SUFFIXES:
        from .mjcf import load_mjcf

        if root != "ground" or package_dirs:
            raise click.UsageError("--root and --package-dir apply to URDF files (an MJCF file places its own free joints)")
        imp = load_mjcf(urdf_file, limits=limits, contours=None)
        header = f"Imported from {urdf_file.name} by mechsys import (MJCF, limits = {limits})."
        if imp.ignored:
            header += "\nNot imported: " + "; ".join(imp.ignored)
    else:
        from .urdf import load_urdf

        imp = load_urdf(urdf_file, root=root, limits=limits, package_dirs=list(package_dirs), contours=None)
        header = f"Imported from {urdf_file.name} by mechsys import (root = {root}, limits = {limits})."
    out = out if out is not None else urdf_file.with_suffix(".toml")
    out.write_text(dumps(imp.model.to_dict(), header + limits_header(imp)), encoding="utf-8")
    click.echo(f"wrote {out} ({len(imp.model.body_info())} bodies, {len(imp.model.joint_info())} joints, nu = {imp.model.nu})")


@cli.command()
@click.argument("results_file", metavar="RESULTS.h5", type=click.Path(path_type=Path, dir_okay=False))
def signals(results_file: Path) -> None:
    """List the signals of a results file with their units and shapes."""
    from .results import load

    res = load(results_file)
    rows = []
    for n in res.names():
        shape = "(" + ", ".join(str(s) for s in res[n].shape) + ("," if res[n].ndim == 1 else "") + ")"
        rows.append((n, res.unit(n) or "-", shape))
    click.echo(_table(["signal", "unit", "shape"], rows, indent=""))


def _pair(text: str, option: str, parts: int, form: str) -> list[str]:
    """``text`` split at colons into ``parts`` non-empty fields, or a CliError naming ``option``."""
    fields = [p.strip() for p in text.split(":")]
    if len(fields) != parts or not all(fields):
        raise CliError(f"{option}: expected {form}, got '{text}'")
    return fields


def _coordinate(lin: Any, name: str, option: str) -> int:
    """Index of a coordinate of the linear model from a name or an index, or a CliError."""
    from .errors import SettingsError

    try:
        return lin._index(int(name) if name.lstrip("-").isdigit() else name, option)
    except SettingsError as e:
        raise CliError(f"{option}: {str(e).split(': ', 2)[-1]}") from None


def _campbell_option(text: str) -> tuple[str, Any]:
    """JOINT:START:STOP:N into the joint name and the speeds (rad/s)."""
    import numpy as np

    joint, *nums = _pair(text, "--campbell", 4, "JOINT:START:STOP:N (speeds in rad/s)")
    try:
        start, stop, n = float(nums[0]), float(nums[1]), int(nums[2])
    except ValueError:
        raise CliError(f"--campbell: START and STOP must be numbers and N an integer, got '{text}'") from None
    if n < 2 or not (np.isfinite(start) and np.isfinite(stop)) or stop == start:
        raise CliError(f"--campbell: need N >= 2 and finite START != STOP, got '{text}'")
    return joint, np.linspace(start, stop, n)


def _frequency_grid(modes: Any, fmin: float | None, fmax: float | None, n: int) -> Any:
    """Log-spaced frequencies (Hz) around the natural frequencies unless given."""
    import numpy as np

    f = modes.natural_frequency[modes.natural_frequency > 1e-9 * max(modes.natural_frequency.max(initial=0.0), 1e-300)]
    lo = fmin if fmin is not None else (0.1 * f.min() if f.size else 0.01)
    hi = fmax if fmax is not None else (3.0 * f.max() if f.size else 100.0)
    for name, v in (("--fmin", lo), ("--fmax", hi)):
        if not (np.isfinite(v) and v > 0):
            raise CliError(f"{name}: must be a frequency > 0 (Hz), got {v:g}")
    if hi <= lo:
        raise CliError(f"--fmax ({hi:g} Hz) must be above --fmin ({lo:g} Hz)")
    if n < 2:
        raise CliError(f"--n: need at least 2 frequencies, got {n}")
    return np.geomspace(lo, hi, n)


@cli.command()
@click.argument("model_file", metavar="MODEL", type=click.Path(path_type=Path, dir_okay=False))
@click.option("--at", "at", type=click.Choice(["q0", "equilibrium", "steady"]), default="q0", show_default=True,
              help="Linearize at the model's q0/u0, at the static equilibrium (found from q0, at rest) or at the steady "
              "motion found from q0/u0 (see --free).")
@click.option("--free", "free", metavar="NAMES", help="With --at steady: coordinates and speeds (with a prime, spin') the "
              "steady-motion solver may change, comma-separated.")
@click.option("--coordinates", "coordinates", metavar="NAMES",
              help="Joint coordinates of the second-order form (e.g. lean,steer for a non-holonomic model), comma-separated.")
@click.option("--check", "check", is_flag=True, help="Check the eigenvalues against small-perturbation runs of the "
              "nonlinear model (exit status 1 when one disagrees by more than 1e-3 relative).")
@click.option("--sweep", "sweep", metavar="SPEED:START:STOP:N",
              help="Eigenvalues at N values START..STOP of a speed (a joint velocity with a prime, e.g. rear_hub') at the "
              "steady motion; plots them with the stable ranges shaded.")
@click.option("--out-dir", type=click.Path(path_type=Path, file_okay=False), default=Path("results"), show_default=True,
              help="Folder for the plots.")
@click.option("--frf", "frf", metavar="IN:OUT", help="Bode plot from a generalized force on coordinate IN to coordinate OUT "
              "(names or indices) [default: the first coordinate to itself].")
@click.option("--fmin", type=float, help="Lowest FRF frequency (Hz) [default: 0.1 x the lowest natural frequency].")
@click.option("--fmax", type=float, help="Highest FRF frequency (Hz) [default: 3 x the highest natural frequency].")
@click.option("--n", "n_freq", type=int, default=500, show_default=True, help="Number of FRF frequencies (log-spaced).")
@click.option("--campbell", "campbell", metavar="JOINT:START:STOP:N",
              help="Campbell diagram: re-linearize with the spin joint's velocity at N speeds START..STOP (rad/s).")
@click.option("--whirl", metavar="X,Y", help="Coordinates of the whirl plane (x then y, right-handed with the spin axis) "
              "to tell forward from backward whirl.")
@click.option("--contacts", "contacts", type=click.Choice(["refuse", "hold", "roll"]), default="refuse", show_default=True,
              help="What a contact closed at the point becomes: refused, held closed sliding frictionlessly, or held "
              "closed rolling without slip.")
def linear(model_file: Path, at: str, free: str | None, coordinates: str | None, check: bool, sweep: str | None,
           out_dir: Path, frf: str | None, fmin: float | None, fmax: float | None, n_freq: int, campbell: str | None,
           whirl: str | None, contacts: str) -> None:
    """Linear vibration analysis of a model file about an equilibrium or a steady motion: modes,
    a Bode plot, a Campbell diagram, eigenvalues over a speed, a check against the nonlinear model.

    A .py model file is executed as Python code: run only files you trust."""
    import warnings

    from . import linear as lin_mod
    from .errors import SettingsError, SolverError
    from .modelfile import load_model

    model, _ = load_model(model_file)
    names = [c.strip() for c in coordinates.split(",") if c.strip()] if coordinates else None
    if free is not None and at != "steady":
        raise CliError("--free: needs --at steady")
    point_at: object = at
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            if at == "steady":
                point_at = lin_mod.steady_motion(model, free=[c.strip() for c in (free or "").split(",") if c.strip()])
            lin = lin_mod.linearize(model, at=point_at, coordinates=names, contacts=contacts)
        except (SettingsError, SolverError) as e:
            option = ("--contacts" if "contact" in str(e) else "--coordinates" if "coordinates" in str(e)
                      else "--free" if "steady_motion" in str(e) else "--at")
            raise CliError(f"{option}: {e}") from None
    if lin.n == 0:
        raise CliError(f"{model_file}: the model has no degree of freedom to analyse")
    modes = lin.modes()
    point = ", ".join(f"{j['name']} = " + (f"{lin.q[j['iq']]:.6g}" if j["nq"] == 1 else _fmt_vec(lin.q[j["iq"]:j["iq"] + j["nq"]]))
                      for j in model.joint_info() if j["nq"])
    click.echo(f"model     {model.name} ({model_file}), {lin.n} coordinates: {', '.join(lin.names)}")
    click.echo(f"point     {'static equilibrium' if at == 'equilibrium' else 'q0, u0'}: {point or '-'}")
    click.echo(f"residual  {float(abs(lin.residual).max(initial=0.0)):.4g} (largest |V^T M u'| at the point)")
    if bool(abs(lin.u).max(initial=0.0)):
        click.echo(f"motion    {'steady' if lin.steady else 'NOT steady'}; cyclic: {', '.join(lin.cyclic) or '-'}; "
                   f"first-order states: {', '.join(lin.states)}")
    for w in caught:
        click.echo(f"warning: {w.message}" + ("; try --at equilibrium" if at == "q0" else ""))
    click.echo("")
    click.echo(modes.table())
    click.echo("stable" if modes.stable else f"unstable: modes {', '.join(str(k + 1) for k in modes.unstable)}")
    if modes.shapes.shape[0]:
        shape_names = lin.names if lin.M is not None else lin.state.keep_names
        click.echo("mode shapes (largest coordinate 1):")
        click.echo(modes.shapes_table(shape_names))
    click.echo("")
    stem = _safe_name(model.name)
    failed = False
    if check:
        c = lin_mod.check(lin)
        click.echo("check against small-perturbation runs of the nonlinear model:")
        click.echo(c.table())
        failed = c.worst > 1e-3
        click.echo(f"worst relative difference {c.worst:.2e}" + (" (beyond 1e-3)" if failed else ""))
        click.echo("")
    if sweep is not None:
        speed, values = _sweep_option(sweep)
        try:
            sw = lin_mod.sweep(model, values, speed=speed, coordinates=names)
        except (SettingsError, SolverError) as e:
            raise CliError(f"--sweep: {e}") from None
        sweep_path = out_dir / f"{stem}_sweep.png"
        sw.plot(out=sweep_path, title=f"{model.name}: eigenvalues against {speed}")
        ranges = ", ".join(f"{a:.6g} .. {b:.6g}" for a, b in sw.stable_ranges()) or "none"
        click.echo(f"sweep     {speed} at {values.size} values {values[0]:g} .. {values[-1]:g}: stable {ranges}: {sweep_path}")
    if lin.M is None:
        click.echo(f"no second-order form ({lin.state.why_first_order}): no Bode plot; name coordinates with --coordinates")
        if failed:
            raise SystemExit(1)
        return
    i, o = (0, 0) if frf is None else (_coordinate(lin, s, "--frf") for s in _pair(frf, "--frf", 2, "IN:OUT"))
    freqs = _frequency_grid(modes, fmin, fmax, n_freq)
    bode_path = out_dir / f"{stem}_bode.png"
    lin_mod.bode(lin, freqs, input=i, output=o, out=bode_path, title=f"{model.name}: {lin.names[i]} -> {lin.names[o]}")
    click.echo(f"bode      {lin.names[i]} -> {lin.names[o]}, {freqs.size} frequencies {freqs[0]:.4g} .. {freqs[-1]:.4g} Hz: {bode_path}")
    if campbell is None:
        if whirl is not None:
            raise CliError("--whirl: needs --campbell")
        if failed:
            raise SystemExit(1)
        return
    joint, speeds = _campbell_option(campbell)
    from .errors import SettingsError

    try:
        diagram = lin.campbell(speeds, joint=joint, whirl=whirl)
    except SettingsError as e:
        msg = str(e).split(": ", 1)[-1]
        option = "--whirl" if msg.startswith("whirl") else "--campbell"
        raise CliError(f"{option}: {msg.removeprefix('whirl: ')}") from None
    camp_path = out_dir / f"{stem}_campbell.png"
    diagram.plot(out=camp_path, orders=(1.0, 2.0), title=f"{model.name}: Campbell diagram")
    click.echo(f"campbell  '{joint}' at {speeds.size} speeds {speeds[0]:g} .. {speeds[-1]:g} rad/s: {camp_path}")
    for cs in diagram.critical_speeds():
        kind = f", {cs['whirl']} whirl" if cs["whirl"] else ""
        click.echo(f"critical  {cs['speed']:.6g} rad/s ({cs['speed'] * 30 / 3.141592653589793:.6g} rpm): mode {cs['mode'] + 1}{kind}")
    if failed:
        raise SystemExit(1)


def _sweep_option(text: str):
    """(speed, values) from SPEED:START:STOP:N."""
    import numpy as np

    parts = text.rsplit(":", 3)
    if len(parts) != 4:
        raise CliError(f"--sweep: expected SPEED:START:STOP:N, got {text!r}")
    try:
        lo, hi, n = float(parts[1]), float(parts[2]), int(parts[3])
    except ValueError:
        raise CliError(f"--sweep: START, STOP must be numbers and N an integer, got {text!r}") from None
    if n < 2 or not (np.isfinite(lo) and np.isfinite(hi)) or lo == hi:
        raise CliError(f"--sweep: need N >= 2 and finite START != STOP, got {text!r}")
    return parts[0], np.linspace(lo, hi, n)


from .cli_study import study_cmd  # noqa: E402  (parameter studies, mechsys study)

cli.add_command(study_cmd)

from .cli_batch import batch_cmd  # noqa: E402  (batch simulation, mechsys batch)

cli.add_command(batch_cmd)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``mechsys`` console script; returns the exit status."""
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="mechsys", standalone_mode=True)
    except SystemExit as e:
        code = e.code
        if code is None:
            return 0
        if isinstance(code, int):
            return code
        click.echo(str(code), err=True)
        return 1
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
