"""LaTeX of the closed-form terms: one term, or a document with all of them.

Joint symbols print as ``q_1``, ``\\dot{q}_1``, ``\\ddot{q}_1``; ``sin q_1`` and ``cos q_1``
as ``s_1`` and ``c_1`` (defined at the top of the document), which keeps the formulas
of a small robot readable. The passive joint forces ``tau_p`` (friction and springs) print
with sympy's ``\\operatorname{sign}`` (or ``\\tanh``); the document has their section and
their term in the equation of motion when the model has some. A model with mimic joints lists
them with their coordinate ``r q_k + o`` (:mod:`.mimic`).
"""

from __future__ import annotations

import sympy as sp

from ._ring import readable_numbers
from .model import joint_motion

_DESCRIPTION = {
    "M": "Mass matrix $M(q)$",
    "C": r"Christoffel matrix $C(q, \dot q)$ ($\dot M - 2C$ is skew-symmetric)",
    "C_v": r"Coriolis and centrifugal forces $C(q, \dot q)\,\dot q$",
    "g": "Gravity forces $g(q)$",
    "T": "Kinetic energy $T$",
    "U": "Potential energy $U$ (gravity and joint springs)",
    "L": "Lagrangian $L = T - U$",
    "tau_p": r"Passive joint forces $\tau_p = B \dot q + F_c \operatorname{sgn}(\dot q) + K (q - q_{ref})$",
    "tau": r"Joint forces $\tau = M \ddot q + C \dot q + g + \tau_p$",
}
_LHS = {"M": "M", "C": "C", "C_v": r"(C\dot q)", "g": "g", "tau_p": r"\tau_{p}", "tau": r"\tau", "T": "T", "U": "U",
        "L": "L"}


def _names(eom) -> dict:
    names = {}
    for k in range(eom.n):
        names[eom.q[k]] = f"q_{{{k + 1}}}"
        names[eom.v[k]] = rf"\dot{{q}}_{{{k + 1}}}"
        names[eom.a[k]] = rf"\ddot{{q}}_{{{k + 1}}}"
        s, c = eom.ring.trig_names(k)
        names[s], names[c] = f"s_{{{k + 1}}}", f"c_{{{k + 1}}}"
    return names


def _tex(eom, e) -> str:

    return sp.latex(readable_numbers(e), symbol_names=_names(eom))


def _entries(eom, name: str) -> list[tuple[str, sp.Expr]]:
    p = eom.polynomials[name]
    rg = eom.ring
    lhs = _LHS[name]
    flat, extra = eom.flat_terms(name)
    e = [rg.expr(x, "symbols") + x_extra for x, x_extra in zip(flat, extra)]
    n = eom.n
    if name in ("M", "C"):
        return [(f"{lhs}_{{{i + 1}{j + 1}}}", e[i * n + j])
                for i in range(n) for j in range(n) if j >= i or name == "C"]
    if name == "tau_p":
        return [(rf"\tau_{{p,{i + 1}}}", x) for i, x in enumerate(e)]
    if isinstance(p, list):
        return [(f"{lhs}_{{{i + 1}}}", x) for i, x in enumerate(e)]
    return [(lhs, e[0])]


def term_latex(eom, name: str) -> str:
    """An ``align*`` environment with one line per entry of the term (``M`` and its
    symmetric entries ``M_ij``, ``j >= i``)."""
    rows = [rf"{lhs} &= {_tex(eom, e)}" for lhs, e in _entries(eom, name)]
    return "\\begin{align*}\n" + " \\\\\n".join(rows) + "\n\\end{align*}"


def _text(name: str) -> str:
    """A name in LaTeX text (underscores escaped)."""
    return name.replace("_", "\\_")


def document(eom) -> str:
    """A complete LaTeX document: the model, the notation and every term."""
    m = eom.model
    passive = any(x != 0 for x in eom.tau_p)  # the section and the term only when there are some
    joints = ", ".join(f"{_text(m.joint_names[b])} ({m.joint_type[b]})" for b in m.independent)
    if m.mimic:  # each mimic joint's coordinate r q_k + o
        joints += "; mimic joints " + ", ".join(
            f"{_text(m.joint_names[i])} ({m.joint_type[i]}) at ${_tex(eom, joint_motion(m, i)[0])}$"
            for i in range(m.nbodies) if i not in m.independent)
    params = ", ".join(f"${sp.latex(s)}$" for s in eom.parameters) or "none (numeric model)"
    notation = ", ".join(f"$s_{{{k + 1}}} = \\sin q_{{{k + 1}}}$, $c_{{{k + 1}}} = \\cos q_{{{k + 1}}}$"
                         for k in range(eom.n) if eom.ring.revolute[k])
    parts = [
        r"\documentclass[10pt]{article}",
        r"\usepackage{amsmath}",
        r"\usepackage[margin=2cm]{geometry}",
        r"\allowdisplaybreaks",
        rf"\title{{Equations of motion of \texttt{{{m.name.replace('_', chr(92) + '_')}}}}}",
        r"\date{}",
        r"\begin{document}",
        r"\maketitle",
        rf"Derived by \texttt{{robodyn.symbolic}} ({eom.method.replace('_', '-')} method). "
        rf"{eom.n} joints: {joints}. Parameters: {params}.",
        "",
        (r"\[ M(q)\,\ddot q + C(q, \dot q)\,\dot q + g(q) + \tau_p(q, \dot q) = \tau \]" if passive
         else r"\[ M(q)\,\ddot q + C(q, \dot q)\,\dot q + g(q) = \tau \]"),
        "",
        f"Notation: {notation}." if notation else "",
    ]
    for name in ("M", "C", "g", *(("tau_p",) if passive else ()), "T", "U", "L", "tau"):
        parts += [rf"\section*{{{_DESCRIPTION[name]}}}", term_latex(eom, name), ""]
    parts.append(r"\end{document}")
    return "\n".join(parts) + "\n"
