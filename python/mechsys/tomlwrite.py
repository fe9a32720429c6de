"""Writing a model description as a TOML model file (the format of docs/model-file.md).

Python's standard library reads TOML but does not write it, and the descriptions hold only
strings, numbers, booleans, lists and tables, so a small writer does: top-level values first,
then each list of tables as ``[[key]]`` entries whose nested tables are written inline. Floats are
written with ``repr``, which round-trips every double exactly, so a written model reads back
bit for bit.
"""

from __future__ import annotations

import json
import math
from typing import Any

from .errors import ModelError


def _value(v: Any, where: str) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        # a JSON string is a valid TOML basic string (the same escapes, \uXXXX included)
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x, f"{where}[{k}]") for k, x in enumerate(v)) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x, f'{where}.{k}')}" for k, x in v.items()) + " }"
    if hasattr(v, "tolist"):
        return _value(v.tolist(), where)
    raise ModelError(f"{where}: a {type(v).__name__} cannot be written to a TOML model file")


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() and k.isascii() else json.dumps(k)


def dumps(desc: dict, header: str | None = None) -> str:
    """The TOML text of a model description (:meth:`mechsys.Model.to_dict`)."""
    lines = [f"# {line}" for line in (header or "").splitlines()]
    tables = []
    for k, v in desc.items():
        if isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            tables.append((k, v))
        elif isinstance(v, list) and not v:
            continue
        else:
            lines.append(f"{_key(k)} = {_value(v, k)}")
    for k, items in tables:
        for i, item in enumerate(items):
            lines.append("")
            lines.append(f"[[{_key(k)}]]")
            for kk, vv in item.items():
                lines.append(f"{_key(kk)} = {_value(vv, f'{k}[{i}].{kk}')}")
    return "\n".join(lines) + "\n"
