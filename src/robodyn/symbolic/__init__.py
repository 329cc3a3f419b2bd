"""Closed-form models with sympy: Lagrange and Newton-Euler derivations, LaTeX, generated code.

    import robodyn as rd
    eom = rd.symbolic.equations_of_motion(rd.models.load("planar_2r"))
    eom.M, eom.C, eom.g, eom.T, eom.U, eom.L, eom.tau     # sympy, in q, v, a
    eom.tau_p                                             # friction and springs: tau = M a + C v + g + tau_p
    M = eom.to_function("M")                              # NumPy, batched: M(q) (..., n, n)
    M = rd.symbolic.recursive_dynamics(model).to_numba("M")   # fast M without deriving
    eom.to_c("out/")                                      # C source and header
    print(eom.latex())                                    # LaTeX document

Symbolic models (:class:`SymbolicModel`) come from a numeric model (:func:`from_model`), a
DH table with symbols (:func:`from_dh`), joint twists (:func:`from_poe`), links and joints
(:class:`ModelBuilder`), or either with named
inertial parameters (:func:`with_inertia_symbols`); :mod:`.textbook` has the textbooks'
robots (``textbook.scara_mls()``, ``elbow_mls()``, ``planar_2r_mls()``); :func:`recursive_dynamics` generates ``M``, ``C v``, ``g``,
``tau`` and ``tau_p`` from the recursions without the expanded derivation; :func:`regressor` gives
``Y(q, v, a)`` with ``tau = Y theta``. A :class:`robodyn.CoupledModel` (mimic joints, :mod:`.mimic`)
gives the terms of its independent coordinates, as the numeric algorithms'. This subpackage imports
sympy; ``import robodyn`` does not import it.
"""

from .builder import ModelBuilder
from .equations import EquationsOfMotion, equations_of_motion
from .model import (SymbolicModel, from_dh, from_model, from_poe, inertia_symbols, inertial_parameters,
                    with_inertia_symbols)
from .recursive import RecursiveDynamics, recursive_dynamics
from .regressor import Regressor, regressor
from . import textbook

__all__ = [
    "EquationsOfMotion", "ModelBuilder", "RecursiveDynamics", "Regressor", "SymbolicModel", "equations_of_motion", "textbook", "from_dh", "from_poe",
    "from_model", "inertia_symbols", "inertial_parameters", "recursive_dynamics", "regressor", "with_inertia_symbols",
]
