r"""
The planar 2R arm in closed form: MLS eq. (4.11)
================================================

Murray, Li and Sastry (*A Mathematical Introduction to Robotic Manipulation*, 1994, section
4.2, eq. 4.11) write the two-link planar arm's inertia matrix with three constants
(:math:`\theta` is robodyn's ``q``),

.. math::

   M(\theta) = \begin{bmatrix} \alpha + 2 \beta \cos\theta_2 & \delta + \beta \cos\theta_2 \\
                \delta + \beta \cos\theta_2 & \delta \end{bmatrix}, \quad
   \alpha = I_{z1} + I_{z2} + m_1 r_1^2 + m_2 (l_1^2 + r_2^2), \;
   \beta = m_2 l_1 r_2, \; \delta = I_{z2} + m_2 r_2^2,

and its Coriolis matrix from the Christoffel symbols of :math:`M`, with
:math:`\beta \sin\theta_2` in every entry but the last. ``rd.symbolic.textbook``
builds the book's arm from its joint twists, with the book's symbols, and derives both with
sympy; here they are printed, checked against the book's form, and then evaluated with the
numbers of robodyn's built-in ``planar_2r`` (thin rods of 10 kg and 5 kg, 1 m long) and
compared with the numeric algorithms ``rd.crba`` and ``rd.coriolis_matrix``.
"""

import matplotlib.pyplot as plt
import numpy as np
import sympy as sp

import robodyn as rd

eom = rd.symbolic.equations_of_motion(rd.symbolic.textbook.planar_2r_mls())
print(sp.pretty(eom.M, wrap_line=False))
print(sp.pretty(eom.C, wrap_line=False))

# %%
# The book's form, exactly (sympy simplifies the difference to zero); the arm of MLS moves in
# a horizontal plane, so its gravity vector is zero.
l1, r1, r2, m1, m2, Iz1, Iz2 = sp.symbols("l1 r1 r2 m1 m2 Iz1 Iz2", positive=True)
q1, q2 = eom.q
qd1, qd2 = eom.v
alpha = Iz1 + Iz2 + m1 * r1 ** 2 + m2 * (l1 ** 2 + r2 ** 2)
beta, delta = m2 * l1 * r2, Iz2 + m2 * r2 ** 2
c2, s2 = sp.cos(q2), sp.sin(q2)
M_book = sp.Matrix([[alpha + 2 * beta * c2, delta + beta * c2], [delta + beta * c2, delta]])
C_book = sp.Matrix([[-beta * s2 * qd2, -beta * s2 * (qd1 + qd2)], [beta * s2 * qd1, 0]])  # from the Christoffel symbols
assert sp.simplify(eom.M - M_book) == sp.zeros(2, 2)
assert sp.simplify(eom.C - C_book) == sp.zeros(2, 2)
assert eom.g == sp.zeros(2, 1)
print(eom.latex("M"))  # the LaTeX of robodyn's report, c2 = cos(q2)
print(eom.latex("C"))

# %%
# The numbers of the built-in arm: centres of mass half way along the rods, ``Iz = m l^2 / 12``,
# so ``alpha = 10``, ``beta = 2.5`` and ``delta = 5 / 3`` kg m^2. The built-in model moves in a
# vertical plane (its gravity is Spong's), but its mass and Coriolis matrices are the same.
values = {l1: 1, r1: sp.Rational(1, 2), r2: sp.Rational(1, 2), m1: 10, m2: 5,
          Iz1: sp.Rational(10, 12), Iz2: sp.Rational(5, 12)}
assert (alpha.subs(values), beta.subs(values), delta.subs(values)) == (10, sp.Rational(5, 2), sp.Rational(5, 3))
M_of = sp.lambdify([eom.q], eom.M.subs(values), "numpy")
C_of = sp.lambdify([eom.q, eom.v], eom.C.subs(values), "numpy")

model = rd.models.load("planar_2r")
rng = np.random.default_rng(0)
q = rng.uniform(-np.pi, np.pi, (5, 2))
v = rng.uniform(-3.0, 3.0, (5, 2))
M = rd.crba(model, q)
C = rd.coriolis_matrix(model, q, v)
for k in range(len(q)):
    print(f"q = {np.round(q[k], 3)}: |M - M_book| = {np.abs(M[k] - M_of(q[k])).max():.1e}, "
          f"|C - C_book| = {np.abs(C[k] - C_of(q[k], v[k])).max():.1e}")
    assert np.allclose(M[k], M_of(q[k]), rtol=1e-13, atol=1e-13)
    assert np.allclose(C[k], C_of(q[k], v[k]), rtol=1e-13, atol=1e-13)

# %%
# :math:`\dot M - 2C` is skew-symmetric (MLS, chapter 4), here with
# :math:`\dot M = \partial M / \partial \theta_2 \, \dot\theta_2` from the closed form.
dM_of = sp.lambdify([eom.q, eom.v], sp.diff(eom.M, q2).subs(values) * qd2, "numpy")
for k in range(len(q)):
    N = dM_of(q[k], v[k]) - 2 * C[k]
    assert np.allclose(N, -N.T, rtol=0, atol=1e-12)

# %%
# The entries of :math:`M` over the elbow angle: ``M11`` swings between
# :math:`\alpha \pm 2\beta` (15 and 5 kg m^2), ``M12`` between :math:`\delta \pm \beta`;
# ``M22`` is constant. Lines: the closed form; dots: ``rd.crba``.
elbow = np.linspace(-np.pi, np.pi, 181)
book = np.array([M_of([0.0, x]) for x in elbow])
dots = elbow[::12]
numeric = rd.crba(model, np.stack([np.zeros_like(dots), dots], axis=-1))
assert np.allclose(book[::12], numeric, rtol=1e-13, atol=1e-13)
assert np.isclose(book[:, 0, 0].max(), 15.0) and np.isclose(book[:, 0, 0].min(), 5.0)

fig, ax = plt.subplots(figsize=(7, 4))
for (i, j), color in zip(((0, 0), (0, 1), (1, 1)), ("C0", "C1", "C2")):
    ax.plot(elbow, book[:, i, j], color=color, label=f"M{i + 1}{j + 1} (MLS eq. 4.11)")
    ax.plot(dots, numeric[:, i, j], "o", color=color, markersize=4)
ax.plot([], [], "ko", markersize=4, label="rd.crba")
ax.set_xlabel("elbow angle q2 (rad)")
ax.set_ylabel("kg m^2")
ax.set_title("Inertia matrix of the planar 2R arm")
ax.legend(fontsize=8)
fig.tight_layout()
