"""Calls by address (``robodyn._jit.by_address``): a kernel calls a large compiled function at
the address of its own code instead of a copy of it, in the compiling process and in a new one
that loads both from the on-disk cache; errors inside the callee reach the caller."""

import base64
import os
import pickle
import subprocess
import sys
import threading

import numpy as np
import pytest
from numba import float64, int64, types

from robodyn._jit import _resolve, by_address, core, kernel


@core
def scaled_sum(x, out, factor):
    """``out = factor x``; returns ``(len(x), sum(out))``. Raises for a negative first entry."""
    if x.shape[0] and x[0] < 0.0:
        raise ValueError("scaled_sum: negative first entry")
    total = 0.0
    for i in range(x.shape[0]):
        out[i] = factor * x[i]
        total += out[i]
    return x.shape[0], total


_scaled_sum = by_address(scaled_sum)


@kernel
def caller(x, factor):
    """The sum of ``factor x`` plus its length, through the call by address."""
    out = np.empty_like(x)
    n, total = _scaled_sum(x, out, factor)
    return total + n


@kernel
def direct_caller(x, factor):
    """:func:`caller` with a direct call (the control: Numba copies the callee in)."""
    out = np.empty_like(x)
    n, total = scaled_sum(x, out, factor)
    return total + n


def _defines_or_declares(dispatcher, name: str) -> bool:
    code = dispatcher.inspect_llvm(dispatcher.signatures[0])
    return any(name in line and line.split()[0] in ("define", "declare") for line in code.splitlines())


def test_the_call_runs_the_callee_s_own_code_and_holds_no_copy():
    x = np.arange(4.0)
    assert caller(x, 1.5) == 1.5 * 6.0 + 4
    assert caller(x, 2) == 2.0 * 6.0 + 4  # a literal or an int argument: the float64 callee, cast
    callee = scaled_sum.overloads[(types.Array(float64, 1, "C"), types.Array(float64, 1, "C"), float64)]
    assert not _defines_or_declares(caller, callee.fndesc.llvm_func_name)  # called through a cell
    assert "robodyn_resolve_address" in caller.inspect_llvm(caller.signatures[0])
    assert direct_caller(x, 1.5) == caller(x, 1.5)
    assert _defines_or_declares(direct_caller, callee.fndesc.llvm_func_name)


def test_an_error_raised_in_the_callee_reaches_the_caller():
    with pytest.raises(ValueError, match="negative first entry"):
        caller(np.array([-1.0, 2.0]), 1.0)


def test_first_calls_from_several_threads_at_once():
    """Every thread's first call resolves the address (the same one) or finds it resolved."""
    results, start = [], threading.Barrier(4)

    @kernel
    def fresh_caller(x):
        out = np.empty_like(x)
        return _scaled_sum(x, out, 3.0)[1]

    def run():
        start.wait()
        results.append(fresh_caller(np.ones(5)))

    threads = [threading.Thread(target=run) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results == [15.0] * 4


def _key(module: str, qualname: str, args, restype) -> bytes:
    return f"{module}|{qualname}|{base64.b64encode(pickle.dumps((args, restype))).decode()}".encode()


def test_the_resolver_gives_zero_for_what_it_cannot_load():
    """An unknown function, or a callee whose return type changed since its caller was
    compiled (a stale cache), has no address: the caller then raises instead of calling it."""
    args = (types.Array(float64, 1, "C"), types.Array(float64, 1, "C"), float64)
    with pytest.warns(RuntimeWarning, match="returns Tuple"):  # (int64, float64), not two int64
        assert _resolve(_key(__name__, "scaled_sum", args, types.UniTuple(int64, 2))) == 0
    assert _resolve(_key(__name__, "scaled_sum", args, types.Tuple((int64, float64)))) != 0
    with pytest.warns(RuntimeWarning, match="no_such_function"):
        assert _resolve(_key(__name__, "no_such_function", args, float64)) == 0
    with pytest.warns(RuntimeWarning, match="no compiled code"):
        assert _resolve(b"not a key") == 0


CHILD = """
import sys
sys.path.insert(0, {tests!r})
import numpy as np
from numba.core import event
import test_by_address as T
with event.install_recorder("numba:compile") as compiled:
    value = T.caller(np.arange(4.0), 1.5)
print(value, len(compiled.buffer))
"""


def test_a_new_process_loads_the_caller_and_the_callee_from_the_cache(tmp_path):
    """The cached caller holds no copy of the callee and needs nothing loaded before it: its
    first call loads the callee's code from the cache too; nothing is compiled."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    script = CHILD.format(tests=os.path.dirname(__file__))
    first = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    second = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    assert first.stdout.split()[0] == second.stdout.split()[0] == "13.0"
    assert int(first.stdout.split()[1]) > 0 and second.stdout.split()[1] == "0"
