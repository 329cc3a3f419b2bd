"""The compilation settings of every kernel, in one place.

``kernel``: a compiled function that may allocate (workspaces, single-state drivers), cached
on disk. ``parallel``: a batch driver whose ``prange`` loop runs on all threads.
``core``: an algorithm's per-state body, and ``inline``: a helper inlined into its callers;
both run without Numba's reference counting (``_nrt=False``), which would otherwise add
atomic increments and decrements of every array passed to a helper (a several-fold slowdown
of the inner loops). They must not allocate (workspaces come from their callers), and an
``inline`` or ``core`` function returns no array that owns memory: a view it returns is made
by ``algorithms._workspace.view`` (which owns none), never an argument or a slice of one,
since a caller that counts references would release it once too often.

``inline`` (and ``exact``) helpers and the ``scratch`` workspace allocators are compiled
without the CPython and C wrappers that a call from Python needs (only compiled code calls
them; a Python call raises ``TypeError``): the wrappers unbox every argument and box the
result, and were generated, optimised and emitted for nothing in every helper.

``inline`` functions are compiled once each, cached on disk like the others, and carry LLVM's
``alwaysinline`` attribute (Numba's ``forceinline``): LLVM copies them into every caller, so
they cost no call, and compiling a kernel costs the sum of its helpers compiled once each
(Numba's own inlining, ``inline="always"``, copies and re-types a helper's IR at every call
site, in time quadratic in its size: the ABA took minutes). Every other kind sets
``forceinline=False`` explicitly, since Numba otherwise inherits the flag from whichever
caller happens to compile a function first.

``fast(*argtypes)``: a single-state entry point compiled for exactly one argument signature
(C-contiguous float64 arrays ``VEC``/``MAT`` for the state and the output, the model's
``MODEL_INTS``/``MODEL_PACKED`` arrays (writeable: see ``layout.KernelTables``), a ``bool``).
Compilation happens (or the cache is loaded) at its first call, not when its module is
imported (importing ``robodyn.simulation`` would otherwise compile the single-state ABA, RNEA,
CRBA, ... that a simulation may never call); the compiled dispatcher then replaces the
placeholder in its module, so that later calls pay nothing for the laziness. It compiles
nothing else: any other argument types (lists, integers, strided or read-only arrays,
batches) raise ``TypeError``, on which the public function takes its general path.

Every kind is cached on disk through :class:`SharedCache`: Numba's cache, with saves locked
between processes, so that processes compiling at once into one cache (``robodyn warmup`` on
every core, the workers of a cluster) never load one another's code for the wrong signature.

All release the GIL (``nogil``), so Python threads run them concurrently (they share no
state: every call allocates its own workspace). ``error_model="numpy"`` lets divisions by
zero give inf/nan instead of raising (the kernels check their inputs and pivots themselves);
``fastmath`` allows fused multiply-add and reassociation but keeps NaN/Inf semantics, so the
finiteness checks stay exact.
"""

import base64
import contextlib
import ctypes
import importlib
import inspect
import itertools
import os
import pickle
import sys
import threading
import warnings

from llvmlite import binding as _llvm
from llvmlite import ir as _ir
from numba import njit
from numba import types as _types
from numba.core import cgutils as _cgutils
from numba.core.caching import FunctionCache, IndexDataCacheFile
from numba.extending import intrinsic as _intrinsic

try:
    import fcntl
except ImportError:  # Windows: saves are not serialised between processes (Numba's own behaviour)
    fcntl = None

FASTMATH = {"contract", "reassoc", "arcp", "nsz"}
_BASE = dict(cache=True, error_model="numpy", fastmath=FASTMATH, nogil=True)
_CALLED = dict(_BASE, forceinline=False)


@contextlib.contextmanager
def _locked(folder: str):
    """Holds an exclusive lock on ``folder``'s cache (a lock file there) between processes."""
    if fcntl is None:
        yield
        return
    with open(os.path.join(folder, ".robodyn-cache.lock"), "a") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


class _SharedIndex(IndexDataCacheFile):
    """Numba's index and data files of one function, saved so that processes compiling at once
    cannot mix up their code: Numba's ``save`` reads the index, picks the first free data file
    number and writes the index, then the data, unlocked; two processes saving two signatures
    of one function at once can both pick number 1, and the index can end up naming the other
    signature's machine code for a signature (a wrong function loaded later). Here a save
    holds a lock on the cache folder from reading the index to writing it, and writes the
    data file before the index that names it (a reader never finds an entry whose data is
    not yet written, or an older file of that number)."""

    def save(self, key, data):
        with _locked(self._cache_path):
            overloads = self._load_index()
            name = overloads.get(key)
            if name is None:
                taken = set(overloads.values())
                name = next(n for n in map(self._data_name, itertools.count(1)) if n not in taken)
            self._save_data(name, data)
            overloads[key] = name
            self._save_index(overloads)


class SharedCache(FunctionCache):
    """Numba's on-disk cache with :class:`_SharedIndex` files: safe when several processes
    (a warm-up on every core, workers of a cluster, test runners) compile into one cache."""

    def __init__(self, py_func):
        super().__init__(py_func)
        self._cache_file = _SharedIndex(cache_path=self._cache_path, filename_base=self._impl.filename_base,
                                        source_stamp=self._impl.locator.get_source_stamp())


def _jit(compiled_callers_only=False, **options):
    """``njit(**options)`` whose dispatchers save to and load from a :class:`SharedCache`;
    ``compiled_callers_only``: a helper that only compiled code calls, compiled without the
    wrappers that let Python and C call it (a call from Python raises ``TypeError``)."""
    def decorate(func):
        if compiled_callers_only:
            dispatcher = njit(no_cpython_wrapper=True, no_cfunc_wrapper=True, **options)(func)
            dispatcher.__class__ = _helper_class(type(dispatcher))
        else:
            dispatcher = njit(**options)(func)
        dispatcher._cache = SharedCache(dispatcher.py_func)
        return dispatcher
    return decorate


_HELPER_CLASSES: dict = {}


def _helper_class(base):
    """``base`` (Numba's dispatcher class) whose instances refuse calls from Python."""
    if base not in _HELPER_CLASSES:
        def __call__(self, *args, **kwargs):
            raise TypeError(f"{self.py_func.__qualname__} is a compiled helper: only compiled code calls it")
        _HELPER_CLASSES[base] = type("CompiledHelper", (base,), {"__call__": __call__})
    return _HELPER_CLASSES[base]


kernel = _jit(**_CALLED)
# ``scratch``: a ``kernel`` that allocates a workspace for compiled callers only (no wrappers:
# boxing its tuple of arrays for Python would be most of its code; a Python call is a TypeError).
scratch = _jit(compiled_callers_only=True, **_CALLED)
parallel = _jit(parallel=True, **_CALLED)
core = _jit(_nrt=False, **_CALLED)
inline = _jit(compiled_callers_only=True, _nrt=False, **dict(_BASE, forceinline=True))
# ``splice``: a tiny helper called with many argument types (a workspace's shapes), spliced
# into each caller's Numba IR (``inline="always"``): cheaper to compile than one machine-code
# function per argument type. Also a large function with one caller (``rollout_at``): a
# separately compiled copy would be optimised and emitted once more inside its caller.
splice = _jit(_nrt=False, inline="always", **_CALLED)
# ``exact``: contraction (fused multiply-add) only, for code whose order of operations
# carries its accuracy (``sincos``); inlined like ``inline``, its flags stay per operation.
exact = _jit(compiled_callers_only=True, _nrt=False, **dict(_BASE, fastmath={"contract"}, forceinline=True))


VEC = _types.Array(_types.float64, 1, "C")
MAT = _types.Array(_types.float64, 2, "C")
TENSOR = _types.Array(_types.float64, 3, "C")
MODEL_INTS = _types.Array(_types.int64, 2, "C")
MODEL_PACKED = _types.Array(_types.float64, 1, "C")
INTS = _types.Array(_types.int64, 1, "C")
BOOLS = _types.Array(_types.boolean, 1, "C")


def fast(*argtypes):
    """Decorator: a kernel returning an int64 status, compiled for ``argtypes`` only, at its
    first call (a :class:`_FirstCall` until then)."""
    signature = _types.int64(*argtypes)
    return lambda func: _FirstCall(func, signature)


class _FirstCall:
    """A :func:`fast` kernel before its first call: compiles it then (once, whichever thread
    calls first) and puts the dispatcher in its place in the defining module."""

    __slots__ = ("dispatcher", "signature", "ready", "_lock", "__wrapped__")

    def __init__(self, func, signature):
        self.dispatcher, self.signature, self.ready = kernel(func), signature, False
        self._lock = threading.Lock()
        self.__wrapped__ = func

    def __call__(self, *args):
        if not self.ready:
            self.compile()
        return self.dispatcher(*args)

    def compile(self):
        """Compile the one signature (a second thread waits here, then finds it ready)."""
        with self._lock:
            if not self.ready:
                self.dispatcher.compile(self.signature)
                self.dispatcher.disable_compile()  # other types raise TypeError
                self.ready = True
                module = sys.modules.get(self.__wrapped__.__module__)
                name = self.__wrapped__.__name__
                if getattr(module, name, None) is self:
                    setattr(module, name, self.dispatcher)  # the module's later calls go straight to it


# -- calls by address ---------------------------------------------------------------------------
#
# Numba copies every compiled function a kernel calls into the kernel's module, to be optimised
# and emitted again there, transitively: a large function called from several kernels (the
# ABA of a simulation step, the contact step of a rollout) is compiled once more inside each.
# :func:`by_address` calls it at the address of its own compiled code instead. The caller's
# module holds a cell for the address (null when it is loaded, from the compiler or the
# on-disk cache) and the key of the callee (its module, name, argument and return types); the
# first call in a process asks :func:`_resolve` (a C callback into Python, registered with
# LLVM under ``RESOLVE``) for the address, which compiles or loads the callee then, and keeps
# it in the cell. So a cached caller needs nothing before it is loaded, and the callee's code
# is its current one.

RESOLVE = "robodyn_resolve_address"


def _resolve(key: bytes) -> int:
    """The address of the compiled code that ``key`` names (``module|qualname|types``, see
    :func:`by_address`), compiled or loaded now; 0 when it cannot be had (the module or name
    is gone, or its return type is no longer the one the caller was compiled against: a
    stale cache), which the caller raises as an error."""
    try:
        module, qualname, blob = key.split(b"|", 2)
        callee = importlib.import_module(module.decode())
        for part in qualname.decode().split("."):
            callee = getattr(callee, part)
        args, restype = pickle.loads(base64.b64decode(blob))
        callee.compile(args)
        compiled = callee.overloads[args]
        if compiled.signature.return_type != restype:
            raise TypeError(f"it returns {compiled.signature.return_type} now, its caller was compiled for {restype}")
        return compiled.library.get_pointer_to_function(compiled.fndesc.llvm_func_name)
    except Exception as e:  # noqa: BLE001 (a C callback must not raise: said here, and the caller raises for the 0)
        warnings.warn(f"robodyn: no compiled code for {key.split(b'|')[:2]}: {e!r}", RuntimeWarning, stacklevel=1)
        return 0


_RESOLVE_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_char_p)(_resolve)
_llvm.add_symbol(RESOLVE, ctypes.cast(_RESOLVE_CALLBACK, ctypes.c_void_p).value)


def by_address(dispatcher):
    """A function for compiled code that calls ``dispatcher`` (a ``core`` or ``kernel``
    function, reachable by its module and qualified name) at the address of its compiled
    code, compiled for the argument types of the call (without their literal values), instead
    of copying that code into the caller (see above). The call cannot be inlined: meant for
    large functions, called once per step or state. An address that cannot be resolved raises
    ``RuntimeError`` in the caller."""
    py_func = dispatcher.py_func
    params = list(inspect.signature(py_func).parameters)
    namespace: dict = {}
    exec(f"def {py_func.__name__}(typingctx, {', '.join(params)}):\n"  # noqa: S102 (the callee's parameter names)
         f"    return type_call(({', '.join(params)},))", namespace)
    name = f"{py_func.__module__}|{py_func.__qualname__}|"

    def type_call(args):
        args = tuple(_types.unliteral(a) for a in args)
        dispatcher.compile(args)
        compiled = dispatcher.overloads[args]
        restype = compiled.signature.return_type
        key = (name + base64.b64encode(pickle.dumps((args, restype))).decode()).encode()
        cell_name = "robodyn.address." + compiled.fndesc.mangled_name

        def codegen(context, builder, signature, llargs):
            module, pointer = builder.module, _ir.IntType(8).as_pointer()
            cell = module.globals.get(cell_name)
            if cell is None:
                cell = _cgutils.add_global_variable(module, pointer, cell_name)
                cell.linkage = "internal"
                cell.initializer = _ir.Constant(pointer, None)
            with builder.if_then(_cgutils.is_null(builder, builder.load(cell)), likely=False):
                resolve = _cgutils.get_or_insert_function(module, _ir.FunctionType(pointer, [pointer]), RESOLVE)
                builder.store(builder.call(resolve, [context.insert_const_bytes(module, key)]), cell)
            address = builder.load(cell)
            with builder.if_then(_cgutils.is_null(builder, address), likely=False):
                context.call_conv.return_user_exc(builder, RuntimeError, (
                    f"the compiled {py_func.__qualname__} could not be loaded (a stale on-disk cache? "
                    f"clear Numba's cache)",))
            callee = builder.bitcast(address, context.call_conv.get_function_type(restype, args).as_pointer())
            status, result = context.call_conv.call_function(builder, callee, restype, args, llargs)
            with _cgutils.if_unlikely(builder, status.is_error):
                context.call_conv.return_status_propagate(builder, status)
            return result

        return restype(*args), codegen

    namespace["type_call"] = type_call
    call = _intrinsic(namespace[py_func.__name__])
    call.dispatcher = dispatcher
    return call
