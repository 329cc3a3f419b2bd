"""Beyond one machine, on Dask: the same API on Dask arrays and clusters.

* Dask arrays in, Dask arrays out: every batched function (``rd.rnea``, ``rd.aba``,
  ``rd.crba``, ``rd.regressor``, the Jacobians, energies and derivatives, ...) takes
  ``dask.array`` states chunked along the batch axes and returns lazy ``dask.array`` results
  (``robodyn.algorithms._lazy``).
* Fleet identification: :func:`robodyn.identification.identify` over many logs (paths or a
  Dask dataframe), each reduced on a worker.
* Monte Carlo simulation: :func:`simulate_many` (:mod:`.montecarlo`).
* Compilation once per worker: the worker plugin :class:`Warmup` (:mod:`.workers`).

Dask is the optional extra ``pip install "robodyn[dask]"``; a laptop's ``LocalCluster`` and a
real cluster (``Client("tcp://scheduler:8786")``, dask-jobqueue, Kubernetes) use the same code.
"""

from __future__ import annotations

from .montecarlo import MonteCarlo, perturbed_model, simulate_many

__all__ = ["MonteCarlo", "Warmup", "perturbed_model", "simulate_many"]


def __getattr__(name: str):
    if name == "Warmup":  # imports distributed: only when asked for
        try:
            from .workers import Warmup
        except ImportError:
            raise ImportError('robodyn.distributed.Warmup needs Dask: pip install "robodyn[dask]"') from None
        return Warmup
    raise AttributeError(f"module 'robodyn.distributed' has no attribute {name!r}")
