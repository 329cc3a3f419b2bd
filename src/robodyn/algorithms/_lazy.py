"""Dask arrays through the batched functions.

Every batched function of ``robodyn.algorithms`` takes ``dask.array`` states as it takes
NumPy arrays, and then returns lazy ``dask.array`` results (a tuple of them where the NumPy
call returns a tuple)::

    q = dask.array.from_zarr("states.zarr")       # (10**9, nq), chunked along the batch
    tau = rd.rnea(model, q, v, a)                 # lazy (10**9, nv), chunked like q
    tau.to_zarr("tau.zarr")                       # computed block by block, in parallel

Each block of states is one task that calls the same function on NumPy arrays, so a block's
result equals the in-memory call on the same states: bit for bit in one process; in another
process to the last bits where a kernel's vectorised sums may be reassociated by the compiler
depending on the arrays' memory alignment (``aba_derivatives``; ``rnea`` is exact). The leading (batch) axes may
be chunked in any way and broadcast as in NumPy; the trailing axes of a state (``nq``,
``nv``, ``(nbodies, 6)``) are brought to one chunk. The model enters the task graph once, as
one key named after a hash of its content (``Model.__dask_tokenize__``): a distributed
scheduler sends it to each worker once, not with every task. An error in a block names the
range of batch indices of that block. Dask is the optional extra ``robodyn[dask]``.
"""

from __future__ import annotations

import inspect

import numpy as np

NQ_ARGS = ("q", "q0", "q1")
NV_ARGS = ("v", "a", "tau", "a_known", "tau_known", "v_ref", "a_ref")


def is_lazy(x) -> bool:
    """True for a Dask collection (anything with a task graph)."""
    t = type(x)
    return t not in _EAGER and hasattr(t, "__dask_graph__")


_EAGER = frozenset((np.ndarray, type(None), float, int, bool, list, tuple, str, np.float64))  # never lazy: quick


def any_lazy(*xs) -> bool:
    """True when one of ``xs`` is a Dask collection: the public functions then return
    :func:`deferred` results."""
    for x in xs:
        if is_lazy(x):
            return True
    return False


def _core(model, name: str) -> tuple:
    if name in NQ_ARGS:
        return (model.nq,)
    if name in NV_ARGS:
        return (model.nv,)
    return (model.nbodies, 6)  # f_ext


def _dask():
    try:
        import dask
        import dask.array as da
    except ImportError:  # pragma: no cover - exercised only without the extra
        raise ImportError('dask arrays need Dask: pip install "robodyn[dask]"') from None
    return dask, da


def _probe(fn, model, batched: dict, options: dict):
    """The function's result on one state (a valid configuration, zero rates): the shapes and
    dtypes of one state's outputs, and whether it returns a tuple."""
    from ..random import random_configuration

    one = {}
    for name in batched:
        if name in NQ_ARGS:
            one[name] = random_configuration(model, np.random.default_rng(0))
        else:
            one[name] = np.zeros(_core(model, name))
    return fn(model, **one, **options)


def _leaves(x) -> list:
    """The arrays of a result, depth first through (named) tuples."""
    return [leaf for item in x for leaf in _leaves(item)] if isinstance(x, tuple) else [x]


def _rebuild(like, leaves):
    """``like``'s structure (tuples, named tuples) with the next of ``leaves`` at each array."""
    if not isinstance(like, tuple):
        return next(leaves)
    items = [_rebuild(item, leaves) for item in like]
    return type(like)(*items) if hasattr(like, "_fields") else tuple(items)


def _block(*arrays, fn, names, model, options, batch):
    """One task: ``fn`` on a block of states (NumPy arrays), its result's arrays in a flat
    tuple (the array itself when there is one); ``arrays[-1]`` holds the flat batch indices of
    the block's states, for the error message."""
    index = arrays[-1]
    try:
        out = _leaves(fn(model, **dict(zip(names, arrays[:-1])), **options))
    except (ValueError, ArithmeticError) as e:
        axes = np.unravel_index([index.min(), index.max()], batch) if batch else ()
        where = ", ".join(f"{lo}:{hi + 1}" for lo, hi in axes)
        raise type(e)(f"{e} [in the Dask block of states [{where}] of the batch {batch}; an index above counts "
                      f"within the block]") from e
    return out[0] if len(out) == 1 else tuple(out)


def _flat_index(da, batch: tuple, chunks: tuple):
    """The flat C-order index of every state of the batch, chunked like the states (lazily:
    each block computes its own part)."""
    index = da.zeros(batch, dtype=np.int64, chunks=chunks)
    stride = 1
    for k in range(len(batch) - 1, -1, -1):
        shape = [1] * len(batch)
        shape[k] = batch[k]
        index = index + da.arange(batch[k], chunks=chunks[k]).reshape(shape) * stride
        stride *= batch[k]
    return index


def deferred(fn, arguments: dict):
    """``fn(**arguments)`` with some state arrays given as Dask arrays: lazy Dask results.

    ``arguments``: the call's arguments by name (the caller's ``locals()`` at its start);
    those named in ``NQ_ARGS``/``NV_ARGS`` and ``f_ext`` are the batched states, anything
    else is passed to every block as it is.
    """
    dask, da = _dask()
    params = {name: arguments[name] for name in inspect.signature(fn).parameters if name in arguments}
    model = params.pop("model")
    params.pop("f_ext_frame", None)  # the old spelling of frame, already folded into it by the caller
    if params.get("out") is not None:
        raise TypeError(f"{fn.__name__}: out= cannot receive a lazy Dask result; assign the returned array")
    params.pop("out", None)
    batched = {name: params.pop(name) for name in list(params)
               if (name in NQ_ARGS or name in NV_ARGS or name == "f_ext") and params[name] is not None}
    for name, x in params.items():
        if is_lazy(x):
            raise TypeError(f"{fn.__name__}: {name} must be in memory (only the states may be Dask arrays)")
    arrays, loop = {}, []
    for name, x in batched.items():
        x = da.asarray(x, dtype=np.float64)
        core = _core(model, name)
        if x.shape[x.ndim - len(core):] != core or x.ndim < len(core):
            shape = ", ".join(["..."] + [str(n) for n in core])
            raise ValueError(f"{name}: expected shape ({shape}), got {x.shape}")
        arrays[name] = x
        loop.append(x.shape[:x.ndim - len(core)])
    try:
        batch = np.broadcast_shapes(*loop)
    except ValueError:
        raise ValueError(f"leading (batch) dimensions do not broadcast: "
                         f"{ {k: x.shape for k, x in arrays.items()} }") from None
    nd = len(batch)
    full = {name: da.broadcast_to(x, batch + x.shape[x.ndim - len(_core(model, name)):])
            for name, x in arrays.items()}
    # one chunk along each state's own axes; the batch axes as the inputs chunk them (unified)
    full = {name: x.rechunk({k: -1 for k in range(nd, x.ndim)}) for name, x in full.items()}
    pairs = [a for name, x in full.items()
             for a in (x, tuple(range(nd)) + tuple(f"{name}{j}" for j in range(x.ndim - nd)))]
    _, unified = da.core.unify_chunks(*pairs)
    chunks = unified[0].chunks[:nd] if unified else ()
    index = _flat_index(da, batch, chunks) if nd else da.asarray(0)

    probe = _probe(fn, model, batched, params)
    outs = _leaves(probe)
    names = list(full)
    sizes, out_sig = {}, []
    for k, o in enumerate(outs):
        dims = [f"o{k}_{j}" for j in range(np.ndim(o))]
        sizes.update(zip(dims, np.shape(o)))
        out_sig.append("(" + ",".join(dims) + ")")
    in_sig = ["(" + ",".join(f"{name}_{j}" for j in range(x.ndim - nd)) + ")" for name, x in zip(names, unified)]
    dtypes = [np.asarray(o).dtype for o in outs]
    result = da.apply_gufunc(
        _block, ",".join(in_sig + ["()"]) + "->" + ",".join(out_sig), *unified, index,
        output_dtypes=tuple(dtypes) if len(outs) > 1 else dtypes[0],
        output_sizes=sizes, vectorize=False, allow_rechunk=False,
        fn=fn, names=names, model=dask.delayed(model, pure=True, traverse=False), options=params,
        batch=batch)
    return _rebuild(probe, iter(result if len(outs) > 1 else [result]))
