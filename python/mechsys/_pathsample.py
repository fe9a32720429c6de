"""Sampling a user's curve r(p) for a path joint (``joints.Path.function``): positions and the
first and second derivatives at equally spaced parameter values, which the engine turns into a
quintic Hermite spline re-parameterized by arc length (``kinematics::path::spline``), so that
the time step never calls back into Python.

The derivatives, in order of preference:

1. the user's own ``df``/``d2f``;
2. forward-mode Taylor arithmetic: ``f`` is called once per sample on a number carrying
   ``(value, d/dp, d²/dp²)`` through ``+ - * / **`` and numpy's elementary functions — exact
   to rounding, no step size;
3. the complex step: ``r' = Im f(p + ih) / h`` (exact to rounding for h = 1e-20 |p|) and
   ``r'' = Im(f(p + hw) + f(p - hw)) / h²`` with ``w = exp(iπ/4)`` (``w² = i``: the odd terms
   cancel, the error is ``h⁴ r⁽⁶⁾/360`` plus rounding ``ε |r'| / h``, h a twentieth of the
   sample spacing: about 1e-11 relative for a smooth curve);
4. central differences of fourth order (about 1e-9 in r', 1e-7 in r''), for functions that
   take neither (``math.cos`` on plain floats).

The spline's own error is at most ``h⁶ max|r⁽⁶⁾| / 46080`` in position (h the sample spacing);
:func:`sample` also measures it at the interval midpoints against ``f`` itself.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from .errors import ModelError

# ---- forward-mode Taylor arithmetic to second order --------------------------------------------


class _Taylor2:
    """x(p) as (value, first derivative, second derivative) at one p."""

    __slots__ = ("v", "d", "dd")
    __array_priority__ = 1000

    def __init__(self, v, d=0.0, dd=0.0):
        self.v, self.d, self.dd = float(v), float(d), float(dd)

    @staticmethod
    def lift(x) -> "_Taylor2":
        if isinstance(x, _Taylor2):
            return x
        if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
            raise TypeError(f"unsupported operand {x!r}")
        return _Taylor2(x)

    def chain(self, f0, f1, f2) -> "_Taylor2":
        """g(x(p)) from g, g', g'' at x: (g x)' = g' x', (g x)'' = g'' x'^2 + g' x''."""
        return _Taylor2(f0, f1 * self.d, f2 * self.d * self.d + f1 * self.dd)

    def __add__(self, o):
        try:
            o = _Taylor2.lift(o)
        except TypeError:
            return NotImplemented
        return _Taylor2(self.v + o.v, self.d + o.d, self.dd + o.dd)

    __radd__ = __add__

    def __neg__(self):
        return _Taylor2(-self.v, -self.d, -self.dd)

    def __pos__(self):
        return self

    def __sub__(self, o):
        try:
            return self + (-_Taylor2.lift(o))
        except TypeError:
            return NotImplemented

    def __rsub__(self, o):
        try:
            return _Taylor2.lift(o) + (-self)
        except TypeError:
            return NotImplemented

    def __mul__(self, o):
        try:
            o = _Taylor2.lift(o)
        except TypeError:
            return NotImplemented
        return _Taylor2(self.v * o.v, self.d * o.v + self.v * o.d, self.dd * o.v + 2 * self.d * o.d + self.v * o.dd)

    __rmul__ = __mul__

    def _recip(self):
        r = 1.0 / self.v
        return self.chain(r, -r * r, 2 * r * r * r)

    def __truediv__(self, o):
        try:
            return self * _Taylor2.lift(o)._recip()
        except TypeError:
            return NotImplemented

    def __rtruediv__(self, o):
        try:
            return _Taylor2.lift(o) * self._recip()
        except TypeError:
            return NotImplemented

    def __pow__(self, o):
        if isinstance(o, _Taylor2):
            return _exp(o * _log(self))
        k = float(o)
        if k == 0:
            return _Taylor2(1.0)
        return self.chain(self.v**k, k * self.v ** (k - 1), k * (k - 1) * self.v ** (k - 2))

    def __rpow__(self, o):
        return _exp(self * math.log(float(o)))

    def __abs__(self):
        return -self if self.v < 0 else self

    # comparisons on the value (for branches in the user's function)
    def __lt__(self, o):
        return self.v < _Taylor2.lift(o).v

    def __le__(self, o):
        return self.v <= _Taylor2.lift(o).v

    def __gt__(self, o):
        return self.v > _Taylor2.lift(o).v

    def __ge__(self, o):
        return self.v >= _Taylor2.lift(o).v

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        if method != "__call__" or kwargs:
            return NotImplemented
        if ufunc in _BINARY and len(inputs) == 2:
            a, b = inputs
            if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
                # an array with a Taylor number: elementwise, an object array of them
                aa, bb = np.broadcast_arrays(np.asarray(a, dtype=object), np.asarray(b, dtype=object))
                out = np.empty(aa.shape, dtype=object)
                for idx in np.ndindex(aa.shape):
                    out[idx] = _BINARY[ufunc](aa[idx], bb[idx])
                return out
            return _BINARY[ufunc](a, b)
        if ufunc in _UNARY and len(inputs) == 1:
            return _UNARY[ufunc](inputs[0])
        return NotImplemented


def _exp(x):
    e = math.exp(x.v)
    return x.chain(e, e, e)


def _log(x):
    return x.chain(math.log(x.v), 1 / x.v, -1 / (x.v * x.v))


def _sqrt(x):
    r = math.sqrt(x.v)
    return x.chain(r, 0.5 / r, -0.25 / (r * x.v))


def _sin(x):
    s, c = math.sin(x.v), math.cos(x.v)
    return x.chain(s, c, -s)


def _cos(x):
    s, c = math.sin(x.v), math.cos(x.v)
    return x.chain(c, -s, -c)


def _tan(x):
    t = math.tan(x.v)
    s2 = 1 + t * t
    return x.chain(t, s2, 2 * t * s2)


def _arctan(x):
    q = 1 / (1 + x.v * x.v)
    return x.chain(math.atan(x.v), q, -2 * x.v * q * q)


def _arcsin(x):
    q = 1 / math.sqrt(1 - x.v * x.v)
    return x.chain(math.asin(x.v), q, x.v * q**3)


def _arccos(x):
    q = 1 / math.sqrt(1 - x.v * x.v)
    return x.chain(math.acos(x.v), -q, -x.v * q**3)


def _sinh(x):
    s, c = math.sinh(x.v), math.cosh(x.v)
    return x.chain(s, c, s)


def _cosh(x):
    s, c = math.sinh(x.v), math.cosh(x.v)
    return x.chain(c, s, c)


def _tanh(x):
    t = math.tanh(x.v)
    s2 = 1 - t * t
    return x.chain(t, s2, -2 * t * s2)


_UNARY = {
    np.sin: _sin, np.cos: _cos, np.tan: _tan, np.exp: _exp, np.log: _log, np.sqrt: _sqrt, np.arctan: _arctan,
    np.arcsin: _arcsin, np.arccos: _arccos, np.sinh: _sinh, np.cosh: _cosh, np.tanh: _tanh,
    np.negative: lambda x: -x, np.positive: lambda x: x, np.absolute: abs, np.square: lambda x: x * x,
}
# numpy applies a ufunc to an object array by calling the elements' methods of the same name
for _name, _fn in (("sin", _sin), ("cos", _cos), ("tan", _tan), ("exp", _exp), ("log", _log), ("sqrt", _sqrt),
                   ("arctan", _arctan), ("arcsin", _arcsin), ("arccos", _arccos), ("sinh", _sinh), ("cosh", _cosh),
                   ("tanh", _tanh)):
    setattr(_Taylor2, _name, _fn)

_BINARY = {
    np.add: lambda a, b: _Taylor2.lift(a) + b, np.subtract: lambda a, b: _Taylor2.lift(a) - b,
    np.multiply: lambda a, b: _Taylor2.lift(a) * b, np.true_divide: lambda a, b: _Taylor2.lift(a) / b,
    np.power: lambda a, b: _Taylor2.lift(a) ** b,
}


# ---- sampling -----------------------------------------------------------------------------------


def _vector(x, what: str) -> np.ndarray:
    try:
        a = np.asarray(x, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected (x, y, z), got {x!r}") from None
    if a.size == 2:
        a = np.append(a, 0.0)
    if a.size != 3:
        raise ModelError(f"{what}: expected (x, y, z) (or (x, y) in the x-y plane), got {a.size} numbers")
    return a


def _components(y) -> list:
    """f's return value as a list of 3 components (2: z = 0)."""
    comps = list(np.asarray(y, dtype=object).reshape(-1))
    if len(comps) == 2:
        comps.append(0.0)
    if len(comps) != 3:
        raise ModelError(f"f: expected f(p) to return (x, y, z), got {len(comps)} values")
    return comps


def _by_taylor(f, p: np.ndarray):
    r, d1, d2 = (np.empty((p.size, 3)) for _ in range(3))
    for k, pk in enumerate(p):
        out = [_Taylor2.lift(c) for c in _components(f(_Taylor2(pk, 1.0, 0.0)))]
        r[k] = [c.v for c in out]
        d1[k] = [c.d for c in out]
        d2[k] = [c.dd for c in out]
    return r, d1, d2


def _by_complex_step(f, p: np.ndarray, spacing: float):
    w = complex(math.cos(math.pi / 4), math.sin(math.pi / 4))
    h2 = spacing / 20
    r, d1, d2 = (np.empty((p.size, 3)) for _ in range(3))
    for k, pk in enumerate(p):
        r[k] = [float(np.real(c)) for c in _components(f(pk))]
        h = 1e-20 * max(1.0, abs(pk))
        # Python complex numbers: numpy's would turn into floats silently (dropping the step)
        d1[k] = np.imag(np.asarray(_components(f(complex(pk, h))), dtype=complex)) / h
        plus = np.asarray(_components(f(complex(pk) + h2 * w)), dtype=complex)
        minus = np.asarray(_components(f(complex(pk) - h2 * w)), dtype=complex)
        d2[k] = np.imag(plus + minus) / (h2 * h2)
    return r, d1, d2


def _by_differences(f, p: np.ndarray, spacing: float):
    h = spacing / 50
    val = lambda x: np.asarray(_components(f(x)), dtype=float)  # noqa: E731
    r, d1, d2 = (np.empty((p.size, 3)) for _ in range(3))
    for k, pk in enumerate(p):
        f0, f1, f_1, f2, f_2 = val(pk), val(pk + h), val(pk - h), val(pk + 2 * h), val(pk - 2 * h)
        r[k] = f0
        d1[k] = (8 * (f1 - f_1) - (f2 - f_2)) / (12 * h)
        d2[k] = (16 * (f1 + f_1) - (f2 + f_2) - 30 * f0) / (12 * h * h)
    return r, d1, d2


def _plausible(f, p: np.ndarray, d1: np.ndarray, d2: np.ndarray, spacing: float) -> bool:
    """Whether derivatives found without step sizes agree with differences at a few samples (a
    function that quietly drops the imaginary part or the Taylor parts gives wrong ones)."""
    ref = _by_differences(f, p[np.linspace(0, p.size - 1, min(p.size, 5)).astype(int)], spacing)
    idx = np.linspace(0, p.size - 1, min(p.size, 5)).astype(int)
    s1 = np.abs(d1).max() + 1e-300
    s2 = np.abs(d2).max() + s1 / spacing
    return bool(np.abs(ref[1] - d1[idx]).max() <= 1e-5 * s1 and np.abs(ref[2] - d2[idx]).max() <= 1e-3 * s2)


def hermite_midpoints(p: np.ndarray, r: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """The quintic Hermite interpolant at the interval midpoints (as the engine builds it)."""
    h = np.diff(p)[:, None]
    c0, c1, c2 = r[:-1], d1[:-1] * h, d2[:-1] * h * h / 2
    a = r[1:] - (c0 + c1 + c2)
    b = d1[1:] * h - (c1 + 2 * c2)
    c = d2[1:] * h * h - 2 * c2
    c3, c4, c5 = 10 * a - 4 * b + c / 2, -15 * a + 7 * b - c, 6 * a - 3 * b + c / 2
    return c0 + c1 / 2 + c2 / 4 + c3 / 8 + c4 / 16 + c5 / 32


def sample(f: Callable, p_range, samples: int, df: Callable | None = None, d2f: Callable | None = None) -> dict:
    """Samples of f over p_range with derivatives: parameters, points, tangents (dr/dp),
    second_derivatives, the method used for the derivatives and the interpolation error
    measured at the interval midpoints (m)."""
    if not callable(f):
        raise ModelError(f"f: expected a function p -> (x, y, z), got {f!r}")
    try:
        p0, p1 = (float(x) for x in p_range)
    except (TypeError, ValueError):
        raise ModelError(f"p_range: expected (p_start, p_end), got {p_range!r}") from None
    if not (math.isfinite(p0) and math.isfinite(p1) and p1 > p0):
        raise ModelError(f"p_range: expected finite p_start < p_end, got ({p0}, {p1})")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ModelError(f"samples: expected an integer >= 2, got {samples!r}")
    if (df is None) != (d2f is None):
        raise ModelError("df, d2f: give both derivatives of f or neither")
    p = np.linspace(p0, p1, int(samples))
    spacing = p[1] - p[0]
    if df is not None:
        r = np.array([_vector(f(x), "f(p)") for x in p])
        d1 = np.array([_vector(df(x), "df(p)") for x in p])
        d2 = np.array([_vector(d2f(x), "d2f(p)") for x in p])
        method = "user"
    else:
        method = None
        for name, fn in (("taylor", lambda: _by_taylor(f, p)), ("complex step", lambda: _by_complex_step(f, p, spacing)),
                         ("differences", lambda: _by_differences(f, p, spacing))):
            try:
                r, d1, d2 = fn()
            except (TypeError, ValueError, AttributeError, OverflowError):
                continue
            finite = np.all(np.isfinite(r)) and np.all(np.isfinite(d1)) and np.all(np.isfinite(d2))
            if finite and (name == "differences" or _plausible(f, p, d1, d2, spacing)):
                method = name
                break
        if method is None:
            raise ModelError("f: could not be evaluated at the samples (it must return finite (x, y, z) for p in p_range)")
    mid = np.array([_vector(f(x), "f(p)") for x in 0.5 * (p[:-1] + p[1:])])
    error = float(np.abs(hermite_midpoints(p, r, d1, d2) - mid).max())
    return {"parameters": p, "points": r, "tangents": d1, "second_derivatives": d2, "method": method, "error": error}
