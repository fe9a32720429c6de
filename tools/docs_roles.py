"""A griffe extension for the API reference (mkdocs.yml): the docstrings' Sphinx roles
(:class:`Model`, :func:`~mechsys.joints.Free`, :meth:`Model.build`, ...) become mkdocs-autorefs
cross-references to the object they name, looked up as Python would from where the docstring
is (the class, the module, then the package). A role that names nothing in the package, and is
neither a builtin nor another package's name, is a warning; with ``mkdocs build --strict`` the
build fails on it, and on a reference to an object the reference does not show."""

from __future__ import annotations

import builtins
import logging
import re

import griffe

log = logging.getLogger("mkdocs.plugins.mechsys_roles")
ANY_ROLE = re.compile(r":(?:py:)?(?:class|func|meth|attr|mod|data|exc|obj):`[^`]*`?")
ROLE = re.compile(r":(?:py:)?(class|func|meth|attr|mod|data|exc|obj):`([~!.]?)([A-Za-z_][\w.]*)`")
EXTERNAL = ("numpy", "scipy", "matplotlib", "pandas", "xarray", "h5py", "mujoco", "trimesh", "yourdfpy", "click")


class SphinxRoles(griffe.Extension):
    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs) -> None:
        self.collection = loader.modules_collection
        self.visit(pkg)

    def visit(self, obj) -> None:
        if obj.is_alias:
            return
        if obj.docstring is not None:
            obj.docstring.value = ROLE.sub(lambda m: self.replace(obj, m), obj.docstring.value)
            for left in ANY_ROLE.findall(obj.docstring.value):
                log.warning("%s: cannot read the role %r (write :role:`name` or :role:`~dotted.name`)", obj.path, left)
        for member in list(obj.members.values()):
            if not member.is_alias:
                self.visit(member)

    def lookup(self, path: str):
        try:
            found = self.collection[path]
            return found.final_target if found.is_alias else found
        except (KeyError, ValueError, griffe.AliasResolutionError, griffe.CyclicAliasError):
            return None

    def replace(self, obj, m: re.Match) -> str:
        tilde, target = m.group(2), m.group(3)
        shown = target.rsplit(".", 1)[-1] if tilde == "~" else target
        scopes = []
        holder = obj if obj.is_class or obj.is_module else obj.parent
        while holder is not None:
            scopes.append(holder.path)
            holder = holder.parent
        for scope in [None, *scopes]:
            found = self.lookup(target if scope is None else f"{scope}.{target}")
            if found is not None:
                return f"[`{shown}`][{found.path}]"
        if target.split(".")[0] in EXTERNAL or hasattr(builtins, target):
            return f"`{shown}`"
        log.warning("%s: %s names nothing in the package", obj.path, m.group(0))
        return f"`{shown}`"
