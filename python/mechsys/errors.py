"""The mechsys exception tree.

Every error raised by mechsys derives from :class:`MechsysError`; errors about user input also
derive from :class:`ValueError`, so ``except ValueError`` keeps working for callers that expect it.
"""

from __future__ import annotations


class MechsysError(Exception):
    """Base class of all mechsys errors."""


class ModelError(MechsysError, ValueError):
    """The model (or model file) is inconsistent or non-physical; the message names the item."""


class SettingsError(MechsysError, ValueError):
    """Simulation settings or arguments are invalid; the message names the setting."""


class SolverError(MechsysError, RuntimeError):
    """The numerical solution failed (divergence, step-size underflow, non-convergence)."""


class PainleveError(SolverError):
    """A Painleve situation: with the sliding friction the contact problem has no solution (or
    several); the message names the contacts, the time, mu and the critical mu."""


class SingularityError(MechsysError, ValueError):
    """A kinematic parametrization met its singularity (e.g. Euler angles at theta = 0)."""


class CallbackError(MechsysError, RuntimeError):
    """A user-supplied Python callback raised or returned an invalid value."""


class ResultsError(MechsysError, ValueError):
    """A results file cannot be read or a signal does not exist."""


__all__ = [
    "MechsysError",
    "ModelError",
    "SettingsError",
    "SolverError",
    "PainleveError",
    "SingularityError",
    "CallbackError",
    "ResultsError",
]
