"""mechsys — mechanical system dynamics.

Build a model (:class:`Model`, :mod:`joints`, :mod:`forces`, :mod:`inertia`), simulate it in the
Rust engine (:func:`simulate`), read named signals with units (:class:`Results`), plot them
(:func:`plot`) and save them to HDF5.
"""

from . import analysis, bearings, constraints, continuum, contours, dynamics, elastic, forces, functions, inertia, joints, kinematics, laws, linear, mechanisms, mjcf, urdf, viewer
from ._core import __version__
from .errors import (
    CallbackError,
    MechsysError,
    ModelError,
    PainleveError,
    ResultsError,
    SettingsError,
    SingularityError,
    SolverError,
)
from .contacts import Contact, ContactGroup, GapContact
from .integrators import APGD, DOPRI5, RK4, Auto, EventDriven, Lemke, MoreauJean, Newton, NSGS, Radau5
from .joints import Frame
from .model import Body, Model
from .results import Results, load
from .simulate import simulate
from .study import Study, StudyError, study
from .urdf import load_urdf
from .viewer import view
from .mjcf import load_mjcf
from .batch import BatchResults, simulate_batch
from .laws import Material
from . import hertz


def plot(results, signals, out=None, **kwargs):
    """Plots signals of a :class:`Results` against time (see :func:`mechsys.plotting.plot`)."""
    from .plotting import plot as _plot

    return _plot(results, signals, out=out, **kwargs)


__all__ = [
    "__version__",
    "Model",
    "Body",
    "Frame",
    "simulate",
    "simulate_batch",
    "BatchResults",
    "study",
    "Study",
    "StudyError",
    "load_urdf",
    "view",
    "viewer",
    "load_mjcf",
    "Results",
    "load",
    "plot",
    "RK4",
    "DOPRI5",
    "Radau5",
    "MoreauJean",
    "EventDriven",
    "NSGS",
    "Newton",
    "Lemke",
    "Auto",
    "APGD",
    "joints",
    "constraints",
    "Contact",
    "ContactGroup",
    "GapContact",
    "Material",
    "hertz",
    "contours",
    "laws",
    "mechanisms",
    "urdf",
    "mjcf",
    "analysis",
    "bearings",
    "forces",
    "functions",
    "inertia",
    "continuum",
    "elastic",
    "dynamics",
    "kinematics",
    "MechsysError",
    "ModelError",
    "SettingsError",
    "SolverError",
    "PainleveError",
    "SingularityError",
    "CallbackError",
    "ResultsError",
]
