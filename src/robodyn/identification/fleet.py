"""Identification from many logs (many robots of a fleet, many sessions): each reduced, all combined.

    identify(model, ["run1.csv", "run2.parquet", log3], preprocess={"cutoff": 10})     # a loop here
    identify(model, paths, preprocess={"cutoff": 10}, client=Client("tcp://host:8786"))  # on Dask workers
    identify(model, dask.dataframe.read_csv("runs/*.csv", blocksize=None), client=client)  # a log per partition

Each log is read where it is reduced (a path by :func:`robodyn.io.log.read_log`, a partition of
a Dask DataFrame by :func:`robodyn.io.log.read_frame`, both with the ``tau`` columns
required), preprocessed when ``preprocess`` is given (:func:`.data.preprocess` with those
keywords, the same for every log: filtering and differentiation run along one log's samples,
all of which its task holds), and reduced to its per-joint triangular factors
(:meth:`.reduced.Reduced.from_log`, one block of samples at a time). Only the factors,
``nv (r + 1)^2`` numbers per log, leave the task; they are combined pairwise in a binary tree,
the tall-skinny QR of Demmel, Grigori, Hoemmen and Langou, "Communication-optimal parallel
and sequential QR and LU factorizations", SIAM J. Sci. Comput. 34(1), 2012. The factor of all
the logs equals (up to rounding) that of their samples stacked into one ``[W y]``, and so do
the estimates (:mod:`.estimation`).

* ``client=None``: a loop in this process, one log in memory at a time (Dask not imported).
* ``client`` a ``dask.distributed.Client``: ``client.map`` of the reduction over the logs
  (the workers must be able to read the paths), the tree by ``client.submit`` of
  :func:`.reduced.combine`, and only the final factors gathered.
* a Dask DataFrame whose partitions each hold one log in the log format: its ``to_delayed``
  partitions reduced by ``dask.delayed`` tasks and combined in a tree of delayed tasks,
  computed by ``client`` if given, else by Dask's default scheduler.

An error in one log is raised as ``ValueError`` naming that log: ``logs[k] (path)`` for the
``k``-th of a list (from 0), ``partition k`` of a DataFrame.
"""

from __future__ import annotations

import inspect
import os
from collections.abc import Mapping

from ..io.log import read_frame, read_log
from .base import BaseParameters
from .data import Log, preprocess as preprocess_log
from .reduced import BLOCK, Reduced, check_block, combine


def check_preprocess(preprocess) -> dict | None:
    """``None``, or the keywords of :func:`.data.preprocess` as a dict (``TypeError`` for
    anything else or an unknown keyword), checked before any log is read."""
    if preprocess is None:
        return None
    if not isinstance(preprocess, Mapping):
        raise TypeError(f"preprocess: expected None or a mapping of preprocess() keywords such as "
                        f"{{'cutoff': 10}}, got {type(preprocess).__name__}")
    try:
        inspect.signature(preprocess_log).bind(None, **preprocess)
    except TypeError as e:
        raise TypeError(f"preprocess: {e}") from None
    return dict(preprocess)


def load_log(source, model, *, preprocess: Mapping | None = None) -> Log:
    """The log of ``source`` ready for the regressor: a :class:`Log` as it is, a path read by
    ``read_log(path, model, require_tau=True)``, a pandas DataFrame by ``read_frame``; then
    ``data.preprocess(log, **preprocess)`` when ``preprocess`` is given. A log without torques,
    or without velocities and accelerations and not preprocessed, is a ``ValueError``."""
    if isinstance(source, Log):
        log = source
    elif isinstance(source, (str, os.PathLike)):
        log = read_log(source, model, require_tau=True)
    elif hasattr(source, "columns") and hasattr(source, "to_numpy"):
        log = read_frame(source, model, require_tau=True)
    else:
        raise TypeError(f"expected a Log, a path or a pandas DataFrame, got {type(source).__name__}")
    if log.tau is None:
        raise ValueError("the log has no torques (tau columns)")
    if preprocess is not None:
        return preprocess_log(log, **preprocess)
    if log.v is None or log.a is None:
        raise ValueError("the log has no velocities and accelerations: preprocess it (identify(..., "
                         "preprocess={'cutoff': ...}) or data.preprocess())")
    return log


def reduce_log(source, model, base: BaseParameters, *, preprocess: Mapping | None = None, block: int = BLOCK,
               label: str | None = None) -> Reduced:
    """Reduced statistics of one log: :func:`load_log`, then ``Reduced.from_log``. With a
    ``label``, any error is raised as ``ValueError("<label>: <message>")``, so that the log is
    named however far from it (a worker) the error surfaces."""
    if label is None:
        return Reduced.from_log(model, base, load_log(source, model, preprocess=preprocess), block=block)
    try:
        return reduce_log(source, model, base, preprocess=preprocess, block=block)
    except Exception as e:
        raise ValueError(f"{label}: {e if isinstance(e, ValueError) else f'{type(e).__name__}: {e}'}") from e


def _reduce_labelled(source, label, model, base, preprocess, block) -> Reduced:
    """:func:`reduce_log` with positional arguments, for ``client.map`` and ``dask.delayed``."""
    return reduce_log(source, model, base, preprocess=preprocess, block=block, label=label)


def _pairwise(items: list, join):
    """``join`` applied in a binary tree: ``[a, b, c, d, e] -> [ab, cd, e] -> [abcd, e] -> abcde``."""
    while len(items) > 1:
        joined = [join(items[k], items[k + 1]) for k in range(0, len(items) - 1, 2)]
        items = joined + items[2 * len(joined):]
    return items[0]


def is_dask_frame(x) -> bool:
    """Whether ``x`` is a Dask DataFrame (checked without importing Dask)."""
    return type(x).__module__.split(".")[0] == "dask" and hasattr(x, "to_delayed") and hasattr(x, "npartitions")


def reduce_logs(model, base: BaseParameters, logs, *, preprocess: Mapping | None = None, client=None,
                block: int = BLOCK) -> Reduced:
    """Reduced statistics of the samples of all ``logs`` (module docstring).

    ``logs``: one log (a :class:`Log` or a path), a list or tuple of logs (``Log`` objects,
    paths of CSV or Parquet files, pandas DataFrames), a Dask DataFrame (a log per partition),
    or :class:`.reduced.Reduced` statistics (returned as they are, their shape checked).
    ``preprocess``: None or the keywords of :func:`.data.preprocess` for every log;
    ``client``: a ``dask.distributed.Client`` or None; ``block``: samples per block of the
    regressor.
    """
    preprocess = check_preprocess(preprocess)
    block = check_block(block)
    if isinstance(logs, Reduced):
        if (logs.nv, logs.count) != (model.nv, base.count):
            raise ValueError(f"reduced statistics of (nv, r) = ({logs.nv}, {logs.count}); the model and its base "
                             f"parameters have ({model.nv}, {base.count})")
        return logs
    if is_dask_frame(logs):
        return _reduce_frame(model, base, logs, preprocess, client, block)
    if isinstance(logs, (Log, str, os.PathLike)):
        if client is None:
            return reduce_log(logs, model, base, preprocess=preprocess, block=block)
        logs = [logs]
    if not isinstance(logs, (list, tuple)):
        raise TypeError(f"logs: expected a Log, a path, a list or tuple of them, a Dask DataFrame or Reduced "
                        f"statistics, got {type(logs).__name__}")
    if not logs:
        raise ValueError("logs: the list is empty")
    labels = [f"logs[{k}] ({s})" if isinstance(s, (str, os.PathLike)) else f"logs[{k}]" for k, s in enumerate(logs)]
    if client is None:
        total = None
        for source, label in zip(logs, labels):
            one = reduce_log(source, model, base, preprocess=preprocess, block=block, label=label)
            total = one if total is None else total + one
        return total
    # pure=False: a file read again may have changed since the last call
    model_f, base_f = client.scatter([model, base], broadcast=True)
    parts = client.map(_reduce_labelled, list(logs), labels, model=model_f, base=base_f, preprocess=preprocess,
                       block=block, pure=False)
    return _pairwise(parts, lambda a, b: client.submit(combine, a, b, pure=False)).result()


def _reduce_frame(model, base, frame, preprocess, client, block) -> Reduced:
    """A Dask DataFrame's partitions reduced as logs by delayed tasks, combined in a tree."""
    import dask

    model_d, base_d = dask.delayed(model, traverse=False), dask.delayed(base, traverse=False)
    parts = [dask.delayed(_reduce_labelled)(part, f"partition {k}", model_d, base_d, preprocess, block)
             for k, part in enumerate(frame.to_delayed())]
    total = _pairwise(parts, dask.delayed(combine))
    return client.compute(total).result() if client is not None else total.compute()


__all__ = ["check_preprocess", "load_log", "reduce_log", "reduce_logs", "is_dask_frame"]
