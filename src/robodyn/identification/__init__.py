"""Identification of inertial parameters, joint friction and joint springs.

    import robodyn as rd
    from robodyn import identification as ident

    model = rd.models.load("panda")
    base = ident.base_parameters(model, damping=True, coulomb=True)       # 43 + 14 columns
    exc = ident.optimize_excitation(model, base, period=10, harmonics=5)   # Fourier series
    exc.trajectory.to_csv("traj.csv", model, duration=20, rate=200)
    log = ident.preprocess(ident.read_log("data.csv", model), cutoff=10)  # filter, differentiate
    result = ident.identify(model, log, method="physical", base=base)
    sprung = ident.identify(model, log, stiffness=True, offset=True)      # springs: K, and q_ref from -K q_ref
    rd.write_urdf(result.identified_model(), "identified.urdf")
    ident.write_report(result, log, "report/")
    fleet = ident.identify(model, ["robot1.csv", "robot2.parquet"], preprocess={"cutoff": 10}, base=base,
                           client=None)                                # or a dask.distributed.Client

Modules: :mod:`.base` (base parameters, ``K``, names), :mod:`.excitation` (Fourier series
and their optimisation), :mod:`.data` (CSV logs, filtering, differentiation, decimation),
:mod:`.reduced` (the samples reduced to a triangular factor per joint, combinable),
:mod:`.estimation` (OLS, WLS, physically consistent, from the reduced statistics),
:mod:`.fleet` (many logs, optionally on Dask workers), :mod:`.identify` (the pipeline),
:mod:`.report` (text and plots), :mod:`.cli` (the ``excite`` and ``identify`` commands). The
regressors themselves are :func:`robodyn.regressor` and the energy regressors.
"""

from .base import BaseParameters, base_parameters, parameter_names
from .data import Log, preprocess, read_log, write_log
from .estimation import Estimate, ols, physical, wls
from .fleet import reduce_logs
from .reduced import Reduced
from .excitation import (FourierTrajectory, condition_number, feasible_trajectory, limits_of, optimize_excitation,
                         write_excitation)
from .identify import Identification, identify
from .report import write_report

__all__ = [
    "BaseParameters", "base_parameters", "parameter_names", "Log", "preprocess", "read_log", "write_log",
    "Estimate", "ols", "physical", "wls", "Reduced", "reduce_logs", "FourierTrajectory", "condition_number",
    "feasible_trajectory", "limits_of", "optimize_excitation", "write_excitation", "Identification", "identify",
    "write_report",
]
