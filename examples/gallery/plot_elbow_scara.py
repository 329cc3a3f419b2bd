r"""
The elbow manipulator and the SCARA: closed forms against the numeric model
===========================================================================

Murray, Li and Sastry (*A Mathematical Introduction to Robotic Manipulation*, 1994, chapter
4, Example 4.4) derive the inertia matrices of two classic arms from their joint twists:
the elbow manipulator (a vertical waist, then shoulder and elbow about parallel horizontal
axes) and the SCARA (three vertical revolute joints and a vertical prismatic one). Spong,
Hutchinson and Vidyasagar (*Robot Modeling and Control*, 2006, chapter 3) describe the same
two arms by Denavit-Hartenberg tables, which robodyn's built-in ``elbow_3r`` and ``scara``
follow. ``rd.symbolic.textbook.elbow_mls()`` and ``scara_mls()`` derive MLS's closed forms
with the book's symbols; here they are evaluated with the lengths, masses and inertias of
the built-in arms, after the change of joint coordinates between the two books, and compared
with ``rd.crba`` and ``rd.gravity``.
"""

import matplotlib.pyplot as plt
import numpy as np
import sympy as sp

import robodyn as rd
from robodyn.models import elbow_3r, scara

# %%
# The elbow manipulator
# ---------------------
# robodyn derives the equations of motion as expanded polynomials in the sines and cosines of
# the joint angles; they equal the book's compact form (the waist's inertia couples with
# nothing), and gravity acts on the shoulder and the elbow.
elbow = rd.symbolic.equations_of_motion(rd.symbolic.textbook.elbow_mls())
sym = {s.name: s for s in elbow.model.parameters()}
l1, r1, r2, m2, m3 = (sym[k] for k in ("l1", "r1", "r2", "m2", "m3"))
Iz1, Ix2, Iy2, Iz2, Ix3, Iy3, Iz3 = (sym[k] for k in ("Iz1", "Ix2", "Iy2", "Iz2", "Ix3", "Iy3", "Iz3"))
_, q2, q3 = elbow.q
s2, c2, s23, c23, c3 = sp.sin(q2), sp.cos(q2), sp.sin(q2 + q3), sp.cos(q2 + q3), sp.cos(q3)

M11 = Iy2 * s2 ** 2 + Iy3 * s23 ** 2 + Iz1 + Iz2 * c2 ** 2 + Iz3 * c23 ** 2 + m2 * r1 ** 2 * c2 ** 2 \
    + m3 * (l1 * c2 + r2 * c23) ** 2
M22 = Ix2 + Ix3 + m3 * l1 ** 2 + m2 * r1 ** 2 + m3 * r2 ** 2 + 2 * m3 * l1 * r2 * c3
M23 = Ix3 + m3 * r2 ** 2 + m3 * l1 * r2 * c3
M33 = Ix3 + m3 * r2 ** 2
M_book = sp.Matrix([[M11, 0, 0], [0, M22, M23], [0, M23, M33]])
assert sp.simplify(elbow.M - M_book) == sp.zeros(3, 3)
for name, entry in (("M11", M11), ("M22", M22), ("M23", M23), ("M33", M33)):
    print(f"{name} =", sp.pretty(entry, wrap_line=False).replace("\n", "\n      "))
print("g =", sp.pretty(elbow.g.T, wrap_line=False))

# %%
# MLS's links point along +y at ``q = 0`` and turn about -x; Spong's (the DH table of
# ``elbow_3r``) point along +x and turn about the horizontal axis that raises them for
# positive angles. So the shoulder and elbow angles change sign (and the waist angle, on which
# nothing depends, differs by 90 degrees): ``q_MLS = S q + (-pi/2, 0, 0)`` with
# ``S = diag(1, -1, -1)``, and ``M = S M_MLS S``, ``g = S g_MLS``.
#
# The built-in arm's links are uniform cylinders: the column (5 kg, radius 8 cm) of height
# ``l0 = 0.4`` m, the upper arm (4 kg, radius 4 cm, ``l1 = 0.4`` m) and the forearm (2 kg,
# radius 3 cm, 0.35 m), centres of mass half way along each; a cylinder's inertia is
# ``m r^2 / 2`` about its axis (MLS's ``Iy2``, ``Iy3`` along the links, ``Iz1`` for the column)
# and ``m (3 r^2 + L^2) / 12`` across it.
def cylinder(m, r, L):
    """(axial, transverse) moments of inertia of a uniform cylinder about its centre."""
    return m * r ** 2 / 2, m * (3 * r ** 2 + L ** 2) / 12


(m1, m2, m3), (rad1, rad2, rad3) = elbow_3r.MASSES, elbow_3r.RADII
ax1, tr1 = cylinder(m1, rad1, elbow_3r.D1)
ax2, tr2 = cylinder(m2, rad2, elbow_3r.A2)
ax3, tr3 = cylinder(m3, rad3, elbow_3r.A3)
numbers = dict(l0=elbow_3r.D1, l1=elbow_3r.A2, r0=elbow_3r.D1 / 2, r1=elbow_3r.A2 / 2, r2=elbow_3r.A3 / 2,
               m1=m1, m2=m2, m3=m3, g=9.81, Ix1=tr1, Iy1=tr1, Iz1=ax1, Ix2=tr2, Iy2=ax2, Iz2=tr2,
               Ix3=tr3, Iy3=ax3, Iz3=tr3)
values = {s: numbers[s.name] for s in elbow.model.parameters()}
M_mls = sp.lambdify([elbow.q], elbow.M.subs(values), "numpy")
g_mls = sp.lambdify([elbow.q], elbow.g.subs(values), "numpy")
S = np.diag([1.0, -1.0, -1.0])


def elbow_closed_form(q):
    q_mls = S @ q + np.array([-np.pi / 2, 0.0, 0.0])
    return S @ np.array(M_mls(q_mls), dtype=float) @ S, S @ np.array(g_mls(q_mls), dtype=float).ravel()


model = rd.models.load("elbow_3r")
rng = np.random.default_rng(1)
for q in rng.uniform(-np.pi, np.pi, (4, 3)):
    M_book, g_book = elbow_closed_form(q)
    print(f"q = {np.round(q, 3)}: |M - M_book| = {np.abs(rd.crba(model, q) - M_book).max():.1e}, "
          f"g = {np.round(rd.gravity(model, q), 4)} N m, closed form {np.round(g_book, 4)}")
    assert np.allclose(rd.crba(model, q), M_book, rtol=1e-13, atol=1e-14)
    assert np.allclose(rd.gravity(model, q), g_book, rtol=1e-13, atol=1e-12)

# %%
# In Spong's coordinates the gravity torques are those of a planar two-link arm with the
# centres of mass at ``r1``, ``r2``:
# ``g2 = (m2 r1 + m3 l1) g cos q2 + m3 r2 g cos(q2 + q3)`` and ``g3 = m3 r2 g cos(q2 + q3)``,
# largest when the arm is stretched horizontally. Lines: the closed form; dots: ``rd.gravity``.
shoulder = np.linspace(-np.pi, np.pi, 181)
fig, axes = plt.subplots(1, 2, sharey=True, figsize=(9, 4))
for q3, color in zip((0.0, np.pi / 3, 2 * np.pi / 3), ("C0", "C1", "C2")):
    q = np.stack([np.zeros_like(shoulder), shoulder, np.full_like(shoulder, q3)], axis=-1)
    book = np.array([elbow_closed_form(x)[1] for x in q])
    numeric = rd.gravity(model, q)
    assert np.allclose(numeric, book, rtol=1e-13, atol=1e-12)
    for j, ax in zip((1, 2), axes):
        ax.plot(shoulder, book[:, j], color=color, label=f"q3 = {np.degrees(q3):.0f} deg")
        ax.plot(shoulder[::10], numeric[::10, j], "o", color=color, markersize=3)
for j, ax in zip((2, 3), axes):
    ax.set_xlabel("shoulder angle q2 (rad)")
    ax.set_title(f"gravity torque g{j}(q)")
axes[0].set_ylabel("N m")
axes[0].legend(fontsize=8)
fig.suptitle("Elbow manipulator: MLS's closed form (lines) and rd.gravity (dots)")
fig.tight_layout()

# %%
# The SCARA
# ---------
# MLS's SCARA (Example 4.4) is RRRP: after the two arm joints, a roll joint turns links 3 and
# 4 about the vertical, then a prismatic joint moves link 4 up and down. Its inertia matrix is
# ``[[a + b + 2 c cos q2, b + c cos q2, d, 0], [b + c cos q2, b, d, 0], [d, d, d, 0],
# [0, 0, 0, m4]]`` with the book's ``a, b, c, d``, and only the prismatic joint feels gravity.
scara_eom = rd.symbolic.equations_of_motion(rd.symbolic.textbook.scara_mls())
sym = {s.name: s for s in scara_eom.model.parameters()}
l1, l2, r1, r2, m1, m2, m3, m4, Iz1, Iz2, Iz3, Iz4, g = (sym[k] for k in (
    "l1", "l2", "r1", "r2", "m1", "m2", "m3", "m4", "Iz1", "Iz2", "Iz3", "Iz4", "g"))
a = Iz1 + r1 ** 2 * m1 + l1 ** 2 * (m2 + m3 + m4)
b = Iz2 + Iz3 + Iz4 + l2 ** 2 * (m3 + m4) + m2 * r2 ** 2
c = l1 * l2 * (m3 + m4) + l1 * m2 * r2
d = Iz3 + Iz4
c2 = sp.cos(scara_eom.q[1])
M_book = sp.Matrix([[a + b + 2 * c * c2, b + c * c2, d, 0], [b + c * c2, b, d, 0], [d, d, d, 0], [0, 0, 0, m4]])
assert sp.simplify(scara_eom.M - M_book) == sp.zeros(4, 4)
assert scara_eom.g == sp.Matrix([0, 0, 0, m4 * g])
for name, x in (("a", a), ("b", b), ("c", c), ("d", d)):
    print(f"{name} =", sp.pretty(x, wrap_line=False).replace("\n", "\n    "))
print("g =", sp.pretty(scara_eom.g.T, wrap_line=False))

# %%
# Spong's SCARA (the built-in ``scara``, RRPR) swaps the last two joints: the quill (link 3,
# 1 kg) slides down, and the flange (link 4, 0.5 kg) rolls at its end about the downward
# axis. Every centre of mass beyond the elbow stays on the vertical through the end of link
# 2, so MLS's form holds with MLS's link 3 (the rolling body) taken as the flange, MLS's link 4
# (the sliding mass) as quill plus flange, and the quill's vertical inertia, which turns with
# link 2, added to ``Iz2``. In joint coordinates ``v_MLS = P v`` with ``P`` swapping the last
# two joints and turning both (down instead of up), ``M = P^T M_MLS P`` and ``g = P^T g_MLS``.
n1, n2, n3, n4 = scara.MASSES
_, arm1 = cylinder(n1, 0.05, scara.A1)  # radii and lengths of the module's docstring
_, arm2 = cylinder(n2, 0.04, scara.A2)
quill, _ = cylinder(n3, 0.01, scara.QUILL_LENGTH)
flange, _ = cylinder(n4, 0.04, 0.02)
numbers = dict(l0=scara.D1, l1=scara.A1, l2=scara.A2, r1=scara.A1 / 2, r2=scara.A2 / 2, r3=0.0, r4=0.0, g=9.81,
               m1=n1, m2=n2, m3=0.0, m4=n3 + n4, Iz1=arm1, Iz2=arm2 + quill, Iz3=flange, Iz4=0.0)
values = {s: numbers.get(s.name, 0.0) for s in scara_eom.model.parameters()}  # Ix, Iy: not in M
M_mls = sp.lambdify([scara_eom.q], scara_eom.M.subs(values), "numpy")
g_mls = sp.lambdify([scara_eom.q], scara_eom.g.subs(values), "numpy")
P = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, -1], [0, 0, -1, 0]], dtype=float)

model = rd.models.load("scara")
for q in rng.uniform(model.lower, model.upper, (4, 4)):
    q_mls = P @ q
    M_book = P.T @ np.array(M_mls(q_mls), dtype=float) @ P
    g_book = P.T @ np.array(g_mls(q_mls), dtype=float).ravel()
    print(f"q = {np.round(q, 3)}: |M - M_book| = {np.abs(rd.crba(model, q) - M_book).max():.1e}, "
          f"g = {np.round(rd.gravity(model, q), 4)}")
    assert np.allclose(rd.crba(model, q), M_book, rtol=1e-13, atol=1e-14)
    assert np.allclose(rd.gravity(model, q), g_book, rtol=1e-13, atol=1e-12)
assert np.isclose(g_book[2], -(n3 + n4) * 9.81)  # the quill's joint carries the quill and the flange
