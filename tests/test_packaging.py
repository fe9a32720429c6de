"""The packaging metadata agrees with itself and with the built package: one version in
pyproject.toml, the Cargo workspace and ``mechsys.__version__``; type stubs that cover every public
name of the compiled ``mechsys._core``; the files a wheel needs where maturin looks for them; the
console script and ``python -m mechsys``. (Building a wheel takes minutes on a small machine, so it
is not done here; see README "Install".)"""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
import tomllib
from pathlib import Path

import mechsys as ms
from mechsys import _core

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
MATURIN = PYPROJECT["tool"]["maturin"]


def stub_names() -> tuple[set[str], dict[str, set[str]]]:
    tree = ast.parse((ROOT / "python" / "mechsys" / "_core.pyi").read_text())
    names, classes = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
        if isinstance(node, ast.ClassDef):
            classes[node.name] = {m.name for m in node.body if isinstance(m, ast.FunctionDef)} | {
                m.target.id for m in node.body if isinstance(m, ast.AnnAssign)}
    return names, classes


def test_one_version_everywhere():
    cargo = tomllib.loads((ROOT / "Cargo.toml").read_text())
    assert PYPROJECT["project"]["version"] == cargo["workspace"]["package"]["version"] == ms.__version__ == _core.__version__


def test_stubs_cover_the_compiled_module():
    names, classes = stub_names()
    public = {n for n in dir(_core) if not n.startswith("_")}
    assert public - names == set(), "names of mechsys._core missing from _core.pyi"
    assert names - public - {"__version__"} == set(), "_core.pyi declares names the module does not have"
    for cls, members in classes.items():
        real = {m for m in dir(getattr(_core, cls)) if not m.startswith("_")}
        assert real - members == set(), f"_core.pyi: class {cls} misses members"


def test_maturin_layout():
    src = ROOT / MATURIN["python-source"]
    package, _, ext = MATURIN["module-name"].rpartition(".")
    pkg_dir = src / package.replace(".", "/")
    assert (pkg_dir / "__init__.py").is_file() and (pkg_dir / "__main__.py").is_file()
    assert (pkg_dir / "py.typed").is_file() and (pkg_dir / f"{ext}.pyi").is_file()
    assert (ROOT / MATURIN["manifest-path"]).is_file()
    cargo = tomllib.loads((ROOT / MATURIN["manifest-path"]).read_text())
    assert cargo["lib"]["name"] == ext and "cdylib" in cargo["lib"]["crate-type"]
    # the generated viewer bundle lands inside the package when it exists
    globs = [g["path"] if isinstance(g, dict) else g for g in MATURIN.get("include", [])]
    assert any(g.startswith(f"{MATURIN['python-source']}/{package}/viewer/_bundle/") for g in globs), globs
    assert PYPROJECT["build-system"]["build-backend"] == "maturin"


def test_console_script_and_module_entry_point():
    module, _, func = PYPROJECT["project"]["scripts"]["mechsys"].partition(":")
    assert callable(getattr(importlib.import_module(module), func))
    proc = subprocess.run([sys.executable, "-m", "mechsys", "--version"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == f"mechsys {ms.__version__}"


def test_optional_dependencies_name_the_importers_and_data_libraries():
    extras = PYPROJECT["project"]["optional-dependencies"]
    names = {e: {d.split(">")[0].split("[")[0].split("=")[0] for d in deps} for e, deps in extras.items()}
    assert {"pandas", "xarray"} <= names["data"] and "mujoco" in names["mjcf"] and "mujoco" in names["test"]
    assert {"mkdocs", "mkdocstrings"} <= names["docs"]
