"""The identification pipeline: base parameters, estimation, prediction, identified model.

    base = base_parameters(model, damping=True, coulomb=True)
    result = identify(model, preprocess(read_log("data.csv", model), cutoff=10), method="wls")
    result = identify(model, log, stiffness=True, offset=True)     # joint springs: K and q_ref
    result = identify(model, ["a.csv", "b.csv"], preprocess={"cutoff": 10}, client=client)  # many logs
    result.predict(other_log)          # torques of another motion
    result.identified_model()          # a Model with the estimated parameters

Every estimate is computed from the reduced statistics of the samples (:mod:`.reduced`: a
triangular factor per joint, a block of samples at a time), of one log or of many combined
(:mod:`.fleet`, optionally on Dask workers).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from .._deprecated import renamed_keywords
from ..algorithms.regressor import EXTRA_COLUMNS, extended_parameters
from ..coupling import joint_tree
from ..errors import ModelError, RobodynWarning
from ..joints import NV
from ._blas import one_blas_thread
from .base import BaseParameters, base_parameters
from .data import Log
from .estimation import Estimate, ols, physical, wls
from .fleet import reduce_logs
from .reduced import BLOCK

METHODS = ("ols", "wls", "physical")


@dataclass(frozen=True)
class Identification:
    """Result of :func:`identify`: the nominal ``model``, its ``base`` parameters, the
    ``estimate``, the ``condition_number`` of the stacked base regressor, the nominal
    base parameters ``beta_nominal`` (K times the model's own parameters, offsets
    ``-stiffness * spring_reference``: 0 without springs), the
    number of ``samples`` (of all logs) and the ``singular_values`` (r,) of the stacked base
    regressor, largest first."""

    model: object
    base: BaseParameters
    estimate: Estimate
    condition_number: float
    beta_nominal: np.ndarray
    samples: int
    singular_values: np.ndarray | None = None

    def predict(self, log: Log) -> np.ndarray:
        """Joint torques (N, nv) of the identified model along a log's motion."""
        if log.v is None or log.a is None:
            raise ValueError("predict: the log needs velocities and accelerations; run preprocess() first")
        return self.base.regressor(self.model, log.q, log.v, log.a) @ self.estimate.beta

    def standard_parameters(self) -> np.ndarray:
        """Full parameters ``[theta, extra]``: the physically consistent estimate, or for
        least squares the parameters closest to the nominal ones with the estimated base
        parameters (same torques for every motion)."""
        if self.estimate.theta is not None:
            return self.estimate.theta
        return self.base.completion(self.estimate.beta, self.prior())

    def prior(self) -> np.ndarray:
        return nominal_parameters(self.model, self.base)

    def extra(self) -> dict:
        """Identified per-dof extra parameters by kind (``damping``, ``coulomb``,
        ``stiffness``, ``armature``, ``offset``), in the column order of the regressor (per dof
        of every joint of the tree for a model with mimic joints)."""
        theta = self.standard_parameters()
        out, col, nv = {}, 10 * self.model.nbodies, joint_tree(self.model).nv
        for kind in EXTRA_COLUMNS:
            if self.base.extra.get(kind, False):
                out[kind] = theta[col:col + nv]
                col += nv
        return out

    def identified_model(self):
        """The model with the identified inertial parameters, viscous and Coulomb friction,
        joint springs and armature (offsets have no place in a model: see :meth:`extra`).

        With ``stiffness`` identified, the springs' reference positions come from the offsets:
        the offset of a joint with a spring (``K > 0``) is read as the spring's ``-K q_ref``,
        ``spring_reference = -offset / K`` (so the model's torques are those of the
        estimate); without offset columns the reference is 0 (the estimate's ``K q``). The
        offsets of joints without a spring are dropped.

        Least-squares estimates that are not physically consistent give a model built with
        ``physical="warn"`` (and a :class:`RobodynWarning`); negative friction, stiffness or
        armature is set to 0 with a warning. A negative mass raises :class:`ModelError`: use
        ``method="physical"``.
        """
        theta = self.standard_parameters()
        nb = self.model.nbodies
        changes = {"theta": theta[:10 * nb].reshape(nb, 10)}
        extra = self.extra()
        for kind, values in extra.items():
            if kind in ("damping", "coulomb", "stiffness", "armature"):  # model fields of the same names
                if kind == "stiffness":  # springs sit on joints of one dof: the other columns are 0
                    values = np.where(self._one_dof(), values, 0.0)
                if np.any(values < 0):
                    warnings.warn(f"identified {kind} negative at dofs "
                                  f"{np.flatnonzero(values < 0).tolist()}: set to 0", RobodynWarning, stacklevel=2)
                changes[kind] = np.maximum(values, 0.0)
        if "stiffness" in changes:
            K, offset = changes["stiffness"], extra.get("offset", np.zeros(joint_tree(self.model).nv))
            sprung = K > 0
            changes["spring_reference"] = np.where(sprung, -offset / np.where(sprung, K, 1.0), 0.0)
        try:
            return self.model.replace(**changes, physical="error")
        except ModelError as e:
            if self.estimate.method == "physical":
                raise
            model = self.model.replace(**changes, physical="warn")
            warnings.warn(f"the {self.estimate.method} estimate is not physically consistent ({e}); "
                          "method='physical' gives a consistent one", RobodynWarning, stacklevel=2)
            return model

    def summary(self) -> str:
        e = self.estimate
        lines = [f"Identification of {self.model.name!r} by {e.method.upper()} from {self.samples} samples",
                 f"condition number of the base regressor: {self.condition_number:.4g}",
                 f"residual standard deviation per joint: {np.array2string(e.sigma, precision=4)}",
                 "",
                 f"{'#':>3} {'estimate':>13} {'std':>11} {'std %':>8} {'nominal':>13}  base parameter"]
        for k, name in enumerate(self.base.names):
            lines.append(f"{k + 1:>3} {e.beta[k]:13.6g} {e.std[k]:11.4g} {e.relative_std[k]:8.3g} "
                         f"{self.beta_nominal[k]:13.6g}  {name}")
        return "\n".join(lines)

    def _one_dof(self) -> np.ndarray:
        """(nv,) whether each dof belongs to a joint of one dof (the joints that take springs); of
        every joint of the tree for a model with mimic joints (the extra columns' dofs)."""
        m = joint_tree(self.model)
        one = np.zeros(m.nv, dtype=bool)
        for i in range(m.nbodies):
            if NV[m.joint_type[i]] == 1:
                one[m.idx_v[i]] = True
        return one


def nominal_parameters(model, base: BaseParameters) -> np.ndarray:
    """The model's own ``[theta, extra]`` in the column order of ``base`` (offsets
    ``-stiffness * spring_reference``, the springs' constant torque: 0 without springs)."""
    e = {kind: base.extra.get(kind, False) for kind in EXTRA_COLUMNS}
    return extended_parameters(model, damping=e["damping"], coulomb=e["coulomb"], stiffness=e["stiffness"],
                               armature=e["armature"], offset=True if e["offset"] else None)


@renamed_keywords(viscous="damping")
def identify(model, log, *, method: str = "ols", damping: bool = True, coulomb: bool = True,
             stiffness: bool = False, armature: bool = False, offset: bool = False,
             base: BaseParameters | None = None,
             prior_weight: float = 1e-8, preprocess: dict | None = None, client=None,
             block: int = BLOCK) -> Identification:
    """Identify the base parameters of ``model`` from one log or many.

    Args:
        log: a :class:`Log` with ``q``, ``v``, ``a`` and ``tau`` (``data.preprocess`` fills the
            derivatives) or the path of a log file; many logs as a list or tuple of those
            (pandas DataFrames too), or a Dask DataFrame with one log per partition
            (:mod:`.fleet`); or :class:`.reduced.Reduced` statistics of ``base``'s regressor.
        method: ``"ols"``, ``"wls"`` or ``"physical"`` (see :mod:`.estimation`).
        damping, coulomb, stiffness, armature, offset: the extra columns identified with the
            inertial parameters (ignored when ``base`` is given: its own switches apply). The
            joint springs: ``stiffness=True, offset=True`` identifies their stiffness ``K`` and,
            through the offsets ``-K q_ref``, their reference positions
            (:meth:`Identification.identified_model`).
        base: precomputed base parameters (default :func:`base_parameters` of the model).
        prior_weight: weight of the nominal parameters in ``physical``.
        preprocess: None (every log used as it is: it needs ``v`` and ``a``), or the keywords
            of :func:`.data.preprocess` applied to every log, e.g. ``{"cutoff": 10}``
            (``{}``: differentiation only).
        client: a ``dask.distributed.Client``: the logs are read, preprocessed and reduced on
            its workers, only their triangular factors sent back (:mod:`.fleet`).
        block: samples whose regressor is computed at once (memory ``block nv p`` floats).

    The estimate is that of the base regressor ``W`` and torques ``y`` of all samples stacked,
    computed from their reduced statistics (the triangular factor of ``[W_j y_j]`` per joint,
    :mod:`.reduced`); the condition number is ``sigma_1 / sigma_r`` of the singular values of
    the stacked factor's ``r x r`` block, those of ``W``.
    """
    if method not in METHODS:
        raise ValueError(f"method: expected one of {METHODS}, got {method!r}")
    if base is None:
        base = base_parameters(model, damping=damping, coulomb=coulomb, stiffness=stiffness, armature=armature,
                               offset=offset)
    r = base.count
    with one_blas_thread():
        stats = reduce_logs(model, base, log, preprocess=preprocess, client=client, block=block)
        s = np.linalg.svd(stats.stacked()[:r, :r], compute_uv=False)
        cond = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
        if method == "ols":
            est = ols(stats)
        elif method == "wls":
            est = wls(stats)
        else:
            est = physical(model, base, stats, nominal_parameters(model, base), prior_weight=prior_weight)
    return Identification(model, base, est, cond, base.project(nominal_parameters(model, base)), stats.samples, s)
