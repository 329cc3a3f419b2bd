"""The on-disk cache of compiled code (``robodyn._jit.SharedCache``): processes that compile
into one cache at once (a warm-up on every core, a cluster's workers) never lose an entry or
load another signature's code."""

import subprocess
import sys
import threading

from robodyn._jit import SharedCache, _SharedIndex


def _paused(index, method: str, before: bool = False):
    """Make ``index.<method>`` wait, after it ran (or ``before``), until the second returned
    event is set; the first is set when it waits (the moment another process may come in)."""
    real, inside, go = getattr(index, method), threading.Event(), threading.Event()

    def pause(*args):
        out = None if before else real(*args)
        inside.set()
        assert go.wait(10)
        return real(*args) if before else out

    setattr(index, method, pause)
    return inside, go


def test_two_processes_saving_two_signatures_at_once_keep_both(tmp_path):
    """Process A has read the index when B saves: Numba's own files then both take data file
    1 and one signature is lost (or names the other's code). Here B waits for A's lock."""
    a, b = (_SharedIndex(cache_path=str(tmp_path), filename_base="f", source_stamp=("src", 1)) for _ in range(2))
    inside, go = _paused(a, "_load_index")
    first = threading.Thread(target=a.save, args=("int64", "code for int64"))
    first.start()
    assert inside.wait(10)
    second = threading.Thread(target=b.save, args=("float64", "code for float64"))
    second.start()
    second.join(0.5)
    waited = second.is_alive()
    go.set()
    first.join(10)
    second.join(10)
    assert waited
    later = _SharedIndex(cache_path=str(tmp_path), filename_base="f", source_stamp=("src", 1))
    assert later.load("int64") == "code for int64" and later.load("float64") == "code for float64"


def test_a_reader_never_finds_an_entry_before_its_data(tmp_path):
    """A data file left by an older source has the number a new save takes: while the new
    data is being written, a reader must not load the old file for the new entry."""
    _SharedIndex(cache_path=str(tmp_path), filename_base="f", source_stamp=("old", 1)).save("float64", "old code")
    writer = _SharedIndex(cache_path=str(tmp_path), filename_base="f", source_stamp=("new", 2))
    inside, go = _paused(writer, "_save_data", before=True)
    saving = threading.Thread(target=writer.save, args=("float64", "new code"))
    saving.start()
    assert inside.wait(10)
    reader = _SharedIndex(cache_path=str(tmp_path), filename_base="f", source_stamp=("new", 2))
    seen = reader.load("float64")
    go.set()
    saving.join(10)
    assert seen is None
    assert reader.load("float64") == "new code"


def test_every_kernel_kind_uses_the_shared_cache():
    from robodyn.algorithms import aba, rnea
    from robodyn.algorithms.driver import claim
    from robodyn.simulation import _contact_runs

    for dispatcher in (rnea._rnea_batch.loop, rnea._rnea_batch.run_range, rnea.rnea_state, rnea.motion_step,
                       aba._aba_packed, claim, _contact_runs.rollout_at, _contact_runs.run_workspace):
        assert isinstance(dispatcher._cache, SharedCache), dispatcher


COMPILE = """
import sys
import numpy as np
from robodyn._jit import kernel

@kernel
def twice(x):
    return x + x

x = {"int": np.int64(21), "float": np.float64(0.25), "complex": np.complex128(1j), "int32": np.int32(4)}
print(repr(twice(x[sys.argv[1]])), len(twice.stats.cache_hits))
"""


def test_processes_compiling_one_function_at_once_then_loading_it(tmp_path):
    """Four processes compile four signatures of one function into an empty cache at once; a
    later process loads each from the cache (no compilation) with its own result."""
    script = tmp_path / "twice.py"
    script.write_text(COMPILE)
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PATH": "/usr/bin:/bin"}
    run = [subprocess.Popen([sys.executable, str(script), kind], env=env, stdout=subprocess.PIPE, text=True)
           for kind in ("int", "float", "complex", "int32")]
    assert [p.communicate()[0].split()[0] for p in run] == ["42", "0.5", "2j", "8"]
    for kind, value in (("int", "42"), ("float", "0.5"), ("complex", "2j"), ("int32", "8")):
        out = subprocess.run([sys.executable, str(script), kind], env=env, capture_output=True, text=True, check=True)
        assert out.stdout.split() == [value, "1"], kind
    assert len(list((tmp_path / "cache").rglob("*.nbc"))) == 4
