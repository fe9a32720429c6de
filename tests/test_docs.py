"""`make docs`: the guides and the API reference build with ``mkdocs build --strict``, so a broken
link, anchor or docstring cross-reference fails; and the strict build does fail on each of those
(a small project in a temporary folder with one broken reference of each kind)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mkdocs", reason="the docs build needs mkdocs (make build installs it)")
pytest.importorskip("mkdocstrings_handlers.python", reason="the docs build needs mkdocstrings[python] (make build installs it)")

ROOT = Path(__file__).resolve().parents[1]


def mkdocs_build(config: Path, site: Path) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)]
    return subprocess.run(cmd, capture_output=True, text=True, cwd=config.parent, timeout=120)


def test_strict_build_of_the_docs(tmp_path):
    proc = mkdocs_build(ROOT / "mkdocs.yml", tmp_path / "site")
    assert proc.returncode == 0, proc.stderr
    urdf = (tmp_path / "site" / "api" / "urdf" / "index.html").read_text()
    # a docstring role became a link to the page that documents the target
    assert 'href="../errors/#mechsys.errors.ModelError"' in urdf
    for page in ("usage", "model-file", "contours", "theory", "benchmarks", "api/mjcf", "api/contours", "api/laws"):
        assert (tmp_path / "site" / page / "index.html").is_file(), page


@pytest.mark.parametrize("broken, message", [
    ("role", "pkg.mod.f: :func:`nowhere` names nothing in the package"),
    ("hidden", "Could not find cross-reference target 'pkg.mod._private'"),
    ("unreadable", "cannot read the role ':func:`more <g>`'"),
    ("link", "contains a link 'missing.md', but the target is not found"),
    ("anchor", "no such anchor"),
])
def test_strict_build_fails_on_a_broken_reference(tmp_path, broken, message):
    (tmp_path / "tools").mkdir()
    shutil.copy(ROOT / "tools" / "docs_roles.py", tmp_path / "tools")
    (tmp_path / "pkg").mkdir(parents=True)
    (tmp_path / "pkg" / "pkg").mkdir()
    (tmp_path / "pkg" / "pkg" / "__init__.py").write_text('"""A package."""\n')
    role = {"role": ":func:`nowhere`", "hidden": ":func:`_private`", "unreadable": ":func:`more <g>`"}.get(broken, ":func:`g`")
    (tmp_path / "pkg" / "pkg" / "mod.py").write_text(
        f'"""A module."""\n\n\ndef f():\n    """Calls {role}."""\n\n\ndef g():\n    """Is called."""\n\n\n'
        'def _private():\n    """Hidden."""\n')
    (tmp_path / "docs").mkdir()
    link = {"link": "[more](missing.md)", "anchor": "[more](#nowhere)"}.get(broken, "[more](#a-page)")
    (tmp_path / "docs" / "index.md").write_text(f"# A page\n\nSee {link}.\n\n::: pkg.mod\n")
    (tmp_path / "mkdocs.yml").write_text(
        (ROOT / "mkdocs.yml").read_text().split("nav:")[0]
        + "nav:\n  - index.md\nplugins:\n  - mkdocstrings:\n      handlers:\n        python:\n          paths: [pkg]\n"
        + "          options:\n            docstring_style: sphinx\n            filters: ['!^_']\n"
        + "            extensions: [tools/docs_roles.py:SphinxRoles]\n")
    proc = mkdocs_build(tmp_path / "mkdocs.yml", tmp_path / "site")
    assert proc.returncode != 0
    assert message in proc.stderr, proc.stderr
