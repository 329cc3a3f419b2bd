"""Compilation on the workers of a Dask cluster: :class:`Warmup`, a worker plugin.

Numba compiles robodyn's kernels on first use and keeps them in an on-disk cache
(``NUMBA_CACHE_DIR``, default: ``__pycache__`` next to the installed sources). A worker that
starts with the plugin registered compiles (or loads) them once, before its first task, and
every task then runs compiled code: nothing is compiled per task. Register it once per
cluster; workers that join later run it too::

    client.register_plugin(robodyn.distributed.Warmup(only=["rnea", "aba"]))
"""

from __future__ import annotations

import os

from distributed.diagnostics.plugin import WorkerPlugin


class Warmup(WorkerPlugin):
    """A Dask worker plugin that runs :func:`robodyn.warmup` when a worker starts.

    ``only``: the functions to compile (None: every kernel, about two minutes on an empty
    cache, seconds from a filled one). ``cache_dir``: the Numba cache directory of the
    workers (a path every worker can write, e.g. on a shared or local disk), or None for
    Numba's default.
    """

    name = "robodyn-warmup"

    def __init__(self, only=None, cache_dir: str | None = None):
        self.only = None if only is None else sorted({only} if isinstance(only, str) else set(only))
        self.cache_dir = cache_dir

    def setup(self, worker) -> None:
        if self.cache_dir is not None:
            os.environ["NUMBA_CACHE_DIR"] = str(self.cache_dir)
            from numba.core import config

            config.reload_config()
        from .._warmup import warmup

        warmup(only=self.only)
