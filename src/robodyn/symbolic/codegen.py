"""Code generation from closed-form expressions: NumPy, Numba and C.

A :class:`Program` is a list of expressions (an output array, row-major) in the joint
symbols, with ``sin q_k``, ``cos q_k`` as the plain symbols ``s_k``, ``c_k``, after a
sequence of scalar assignments: either the expanded terms reduced by common-subexpression
elimination (:func:`program`: ``sympy.cse``, or for big programs a table of the distinct
monomials, :func:`monomial_cse`), or the recorded steps of a recursion
(:func:`straight_line`). The same program prints as

* a NumPy function vectorised over leading batch dimensions (:func:`numpy_function`),
* a Numba-compiled function for one state, and a loop over a batch (:func:`numba_function`),
* a C function ``void NAME(const double *q, ..., double *out)`` (:func:`c_function`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp
from sympy.codegen.rewriting import create_expand_pow_optimization

_expand_pow = create_expand_pow_optimization(8)


def _floats(e: sp.Expr) -> sp.Expr:
    """Non-integer rationals as double-precision floats (17 significant digits)."""
    reps = {r: sp.Float(r, 17) for r in e.atoms(sp.Rational) if not r.is_Integer}
    return e.xreplace(reps) if reps else e


@dataclass
class Program:
    """``outputs`` (flat, row-major, of ``shape``) after ``assignments``; ``args``: the
    inputs as ``(name, symbols)``; ``trig``: ``(s_k, "sin", q_k)`` and ``(c_k, "cos", q_k)``
    for each sine and cosine of a joint coordinate that the program uses."""

    name: str
    shape: tuple
    args: list
    trig: list
    assignments: list
    outputs: list
    doc: str = ""

    @property
    def arg_names(self) -> list[str]:
        return [a for a, _ in self.args]


SUM_CHUNK = 32


def _split_sums(assignments, outputs):
    """Sums of more than ``SUM_CHUNK`` terms as partial sums in their own assignments, so
    that no printed expression nests deeper than compilers and Python's parser accept."""
    names = sp.numbered_symbols("y", real=True)
    out_assign = []

    def split(e):
        if isinstance(e, sp.Add) and len(e.args) > SUM_CHUNK:
            parts = []
            args = e.args
            for k in range(0, len(args), SUM_CHUNK):
                y = next(names)
                out_assign.append((y, sp.Add(*args[k:k + SUM_CHUNK])))
                parts.append(y)
            return split(sp.Add(*parts))
        return e

    for s, e in assignments:
        out_assign.append((s, split(e)))
    outputs = [split(e) for e in outputs]
    return out_assign, outputs


# Above this many terms in all, sympy.cse (slow on big expressions) is replaced by the
# monomial table of :func:`monomial_cse`.
CSE_TERMS = 1000


class Text(str):
    """An expression already written in the syntax shared by Python and C (products of
    names, sums of ``coefficient*name``); printed as it is."""


def _fmt(printer, e) -> str:
    return e if isinstance(e, Text) else printer(e)


def monomial_cse(polys, values):
    """Common subexpressions of ring polynomials: every distinct monomial is computed once, as
    an earlier monomial times one generator, and each output is ``sum coef * monomial``
    (partial sums of ``SUM_CHUNK`` terms). ``values[j]``: the sympy value of generator
    ``j``. Returns ``(assignments, outputs, generators used)``; written as :class:`Text`,
    without building sympy expressions, so that tens of thousands of terms take seconds."""
    xs, ys = sp.numbered_symbols("x", real=True), sp.numbered_symbols("y", real=True)
    assignments, names, used = [], {}, set()

    def gen(j):
        used.add(j)
        if j not in names:
            v = values[j]
            if isinstance(v, sp.Symbol):
                names[j] = v.name
            else:
                a = next(xs)
                assignments.append((a, v))
                names[j] = a.name
        return names[j]

    memo = {}

    def mono(m):
        if m in memo:
            return memo[m]
        nz = [j for j, e in enumerate(m) if e]
        if len(nz) == 1 and m[nz[0]] == 1:
            memo[m] = gen(nz[0])
            return memo[m]
        j = nz[-1]
        prev = list(m)
        prev[j] -= 1
        a = mono(tuple(prev))
        x = next(xs)
        assignments.append((x, Text(f"{a}*{gen(j)}")))
        memo[m] = x.name
        return x.name

    outputs = []
    for p in polys:
        terms = []
        for m, c in sorted(p.items()):
            v = int(c.numerator) / int(c.denominator)
            terms.append(repr(v) if not any(m) else f"{v!r}*{mono(m)}")
        while len(terms) > SUM_CHUNK:
            chunks = []
            for k in range(0, len(terms), SUM_CHUNK):
                y = next(ys)
                assignments.append((y, Text(" + ".join(terms[k:k + SUM_CHUNK]))))
                chunks.append(y.name)
            terms = chunks
        outputs.append(Text(" + ".join(terms)) if terms else Text("0.0"))
    return assignments, outputs, {values[j] for j in used}


def program(name: str, exprs, shape: tuple, args: list, trig: list, doc: str = "", polys=None,
            values=None, extra=None) -> Program:
    """Common-subexpression elimination of ``exprs`` (flat list) into a :class:`Program`;
    for big inputs given also as ring ``polys`` with generator ``values``, the monomial
    table of :func:`monomial_cse`. ``extra`` (flat list of sympy expressions in the inputs,
    or None): terms added to the outputs that are not ring polynomials (the joints' passive
    forces and spring energy, with ``q_k`` itself and ``sign``); ``exprs`` leaves them out."""
    extra = [sp.sympify(e) for e in extra] if extra is not None else None
    if polys is not None and sum(len(p) for p in polys) > CSE_TERMS:
        assignments, outputs, used = monomial_cse(polys, values)
        used = set().union(*(v.free_symbols for v in used))
        if extra is not None:  # the ring part named, then the extra term added to it
            names = sp.numbered_symbols("z", real=True)
            for k, e in enumerate(extra):
                if e != 0:
                    z = next(names)
                    assignments.append((z, outputs[k]))
                    outputs[k] = z + _floats(e)
        return Program(name, tuple(shape), args, _used_trig(trig, used), assignments, outputs, doc)
    exprs = [sp.sympify(e) for e in exprs]
    if extra is not None:
        exprs = [e + x for e, x in zip(exprs, extra)]
    if exprs and any(not e.is_number for e in exprs):
        assignments, outputs = sp.cse(exprs, symbols=sp.numbered_symbols("x", real=True), order="none")
    else:
        assignments, outputs = [], exprs
    return _finish(name, shape, args, trig, assignments, outputs, doc)


def straight_line(name: str, assignments, outputs, shape: tuple, args: list, trig: list, doc: str = "") -> Program:
    """A :class:`Program` from assignments ``(symbol, expression)`` in evaluation order (the
    recorded steps of a recursion, :class:`._emit.Emitter`) and ``outputs`` in their
    symbols; assignments that no output needs are dropped."""
    outputs = [sp.sympify(e) for e in outputs]
    need = set().union(set(), *(e.free_symbols for e in outputs))
    kept = []
    for s, e in reversed(assignments):
        if s in need:
            kept.append((s, e))
            need |= e.free_symbols
    return _finish(name, shape, args, trig, kept[::-1], outputs, doc)


def _used_trig(trig, used) -> list:
    """``(symbol, "sin" or "cos", q_k)`` of the sines and cosines in ``used``, from the
    ``(s_k, c_k, q_k)`` of the revolute joints."""
    return [(x, fn, q) for s, c, q in trig for x, fn in ((s, "sin"), (c, "cos")) if x in used]


def _finish(name, shape, args, trig, assignments, outputs, doc) -> Program:
    """Floats for rationals, long sums split, the trigonometric inputs that are used; raises
    ``ValueError`` for symbols that are neither inputs nor assigned."""
    used = set().union(set(), *(e.free_symbols for e in outputs), *(e.free_symbols for _, e in assignments))
    trig = _used_trig(trig, used)
    assignments = [(s, _floats(e)) for s, e in assignments]
    outputs = [_floats(e) for e in outputs]
    assignments, outputs = _split_sums(assignments, outputs)
    known = {s for _, syms in args for s in syms} | {s for s, _, _ in trig}
    known |= {s for s, _ in assignments}
    missing = set().union(*(e.free_symbols for e in outputs), *(e.free_symbols for _, e in assignments)) - known
    if missing:
        raise ValueError(f"{name}: expressions use symbols that are not inputs: {sorted(map(str, missing))}")
    return Program(name, tuple(shape), args, trig, assignments, outputs, doc)


def _statements(prog: Program, printer, unpack: str, trig: str, assign: str) -> list[str]:
    """The statements before the outputs, in one language's templates: the inputs unpacked
    (``unpack`` with ``s, a, k``), the sines and cosines (``trig`` with ``s, fn, q``) and the
    assignments (``assign`` with ``s, e``, ``e`` written by ``printer``)."""
    lines = [unpack.format(s=s, a=a, k=k) for a, syms in prog.args for k, s in enumerate(syms)]
    lines += [trig.format(s=s, fn=fn, q=q) for s, fn, q in prog.trig]
    return lines + [assign.format(s=s, e=_fmt(printer, e)) for s, e in prog.assignments]


# -- NumPy ---------------------------------------------------------------------------------
def numpy_source(prog: Program) -> str:
    from sympy.printing.numpy import NumPyPrinter

    pr = NumPyPrinter({"fully_qualified_modules": True, "allow_unknown_functions": False})
    pr._module = "numpy"
    lines = [f"def {prog.name}({', '.join(prog.arg_names)}):", f'    """{prog.doc}"""']
    for a, syms in prog.args:
        lines.append(f"    {a} = _check({a}, {len(syms)}, {a!r})")
    lines.append(f"    _batch = numpy.broadcast_shapes({', '.join(f'{a}.shape[:-1]' for a in prog.arg_names)})")
    lines += _statements(prog, pr.doprint, "    {s} = {a}[..., {k}]", "    {s} = numpy.{fn}({q})", "    {s} = {e}")
    lines.append(f"    _out = numpy.empty(_batch + {prog.shape!r})")
    for k, e in enumerate(prog.outputs):
        idx = ", ".join(str(i) for i in np.unravel_index(k, prog.shape)) if prog.shape else ""
        lines.append(f"    _out[..., {idx}] = {_fmt(pr.doprint, e)}" if prog.shape
                     else f"    _out[...] = {_fmt(pr.doprint, e)}")
    lines.append("    return _out[()]")
    return "\n".join(lines) + "\n"


def _check(x, n, what):
    if not (type(x) is np.ndarray and x.dtype == np.float64):
        x = np.asarray(x, dtype=float)
    if x.ndim == 0 or x.shape[-1] != n:
        raise ValueError(f"{what}: expected shape (..., {n}), got {x.shape}")
    return x


def numpy_function(prog: Program):
    """The NumPy function of ``prog``: arrays ``(..., n)`` in, ``(...,) + shape`` out."""
    src = numpy_source(prog)
    ns = {"numpy": np, "_check": _check}
    exec(compile(src, f"<robodyn.symbolic {prog.name}>", "exec"), ns)
    f = ns[prog.name]
    f.source = src
    return f


# -- Numba ---------------------------------------------------------------------------------
def _out_index(prog: Program, k: int) -> str:
    """``OUT`` index of output ``k`` in the single-state kernel (scalars: a 1-entry array)."""
    return ", ".join(str(int(i)) for i in np.unravel_index(k, prog.shape)) if prog.shape else "0"


def numba_source(prog: Program) -> str:
    """``NAME_one(inputs..., OUT)``: one state, ``OUT`` of ``shape`` (``(1,)`` for a scalar);
    ``NAME_kernel(INPUTS..., OUT)``: a batch, inputs ``(B or 1, n)``, ``OUT (B,) + shape``."""
    from sympy.printing.pycode import PythonCodePrinter

    pr = PythonCodePrinter({"fully_qualified_modules": True})
    names = prog.arg_names
    lines = [f"def {prog.name}_one({', '.join(names)}, OUT):"]
    lines += _statements(prog, pr.doprint, "    {s} = {a}[{k}]", "    {s} = math.{fn}({q})", "    {s} = {e}")
    for k, e in enumerate(prog.outputs):
        lines.append(f"    OUT[{_out_index(prog, k)}] = {_fmt(pr.doprint, e)}")
    ins = [f"{a.upper()}_" for a in names]
    rows = ", ".join(f"{A}[_b if {A}.shape[0] > 1 else 0]" for A in ins)
    lines += ["", "", f"def {prog.name}_kernel({', '.join(ins)}, OUT):",
              "    for _b in range(OUT.shape[0]):", f"        {prog.name}_one({rows}, OUT[_b])"]
    return "\n".join(lines) + "\n"


def numba_function(prog: Program):
    """The Numba-compiled function of ``prog`` (compiled on first call): same signature and
    shapes as :func:`numpy_function`. One state (1-D float64 arrays of the right sizes) costs
    one compiled call that writes into a new array; other inputs go through the checks of
    :func:`numpy_function` and a compiled loop over the batch."""
    import math

    import numba

    from .._jit import FASTMATH

    src = numba_source(prog)
    ns = {"math": math}
    exec(compile(src, f"<robodyn.symbolic {prog.name} numba>", "exec"), ns)
    # the core kernels' settings: fused multiply-add and reassociation, NaN/Inf semantics kept
    jit = numba.njit(error_model="numpy", fastmath=FASTMATH, nogil=True)
    one = ns[f"{prog.name}_one"] = jit(ns[f"{prog.name}_one"])
    kernel = jit(ns[f"{prog.name}_kernel"])
    shape = prog.shape or (1,)
    sizes = [len(s) for _, s in prog.args]
    names = prog.arg_names

    def batched(*xs):
        batch = np.broadcast_shapes(*(x.shape[:-1] for x in xs))
        B = int(np.prod(batch))
        flat = [np.ascontiguousarray(np.broadcast_to(x, batch + (n,)).reshape(-1, n)) for x, n in zip(xs, sizes)]
        out = np.empty((B,) + shape)
        kernel(*flat, out)
        return out.reshape(batch + prog.shape)

    # a wrapper written out for this signature: one state costs one compiled call
    args = ", ".join(names)
    fast = " and ".join(f"type({a}) is _ndarray and {a}.dtype is _F8 and {a}.shape == ({n},)"
                        for a, n in zip(names, sizes))
    body = [f"def {prog.name}({args}):",
            f"    if {fast}:",
            f"        out = _empty({shape!r})",
            f"        _one({args}, out)",
            f"        return out{'' if prog.shape else '.reshape(())'}"]
    body += [f"    {a} = _check({a}, {n}, {a!r})" for a, n in zip(names, sizes)]
    body += [f"    return _batched({args})"]
    ns = {"_check": _check, "_empty": np.empty, "_ndarray": np.ndarray, "_F8": np.dtype(np.float64),
          "_one": one, "_batched": batched}
    exec("\n".join(body), ns)
    f = ns[prog.name]
    f.__name__ = prog.name
    f.__doc__ = prog.doc
    f.source = src
    f.kernel = kernel
    return f


# -- C -------------------------------------------------------------------------------------
def _c(e) -> str:
    return sp.ccode(_expand_pow(e))


def c_prototype(prog: Program, prefix: str) -> str:
    ins = ", ".join(f"const double *{a}" for a in prog.arg_names)
    return f"void {prefix}_{prog.name}({ins}, double *out)"


def c_function(prog: Program, prefix: str) -> str:
    """C source of ``prog``: inputs ``const double *`` of the joint and parameter vectors,
    ``out`` row-major of ``shape``."""
    lines = [f"/* {prog.doc} */", c_prototype(prog, prefix), "{"]
    lines += _statements(prog, _c, "    const double {s} = {a}[{k}];", "    const double {s} = {fn}({q});",
                         "    const double {s} = {e};")
    for k, e in enumerate(prog.outputs):
        lines.append(f"    out[{k}] = {_fmt(_c, e)};")
    lines.append("}")
    return "\n".join(lines) + "\n"
