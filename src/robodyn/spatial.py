"""Small spatial-algebra helpers for the compiled kernels.

Conventions used inside the kernels (never exposed by the public API):

* A spatial **motion** vector (twist, acceleration, joint axis) is ``m = [v; w]``:
  linear part first (the velocity of the point at the frame origin), angular part last.
* A spatial **force** vector (wrench) is ``f = [f; n]``: force first, moment about the frame
  origin last.
* A **placement** ``aMb = (R, p)`` gives frame ``b`` in frame ``a``: ``R`` (3, 3) rotates
  ``b`` coordinates into ``a`` coordinates and ``p`` (3,) is the origin of ``b`` in ``a``.
  ``act`` maps a vector from ``b`` coordinates to ``a`` coordinates, ``act_inv`` the reverse.
* A rigid-body **inertia** is stored as its 10 inertial parameters about the frame origin,
  in the order ``[m, hx, hy, hz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`` with ``h = m c`` (first
  moment) and ``I`` the rotational inertia about the origin (not the centre of mass).

With this ordering the free-flyer velocity ``[v_lin, omega]`` of the public API is already
a spatial motion vector, and wrenches are ``[force, torque]`` as users write them.

Every helper writes into an output array passed by the caller, so that kernels allocate
nothing in their loops. Reference: R. Featherstone, *Rigid Body Dynamics Algorithms*
(RBDA), Springer 2008, chapter 2 (with the two halves of each vector swapped).
"""

from __future__ import annotations


from ._jit import inline

@inline
def cross3(a, b, out):
    """``out = a x b`` for 3-vectors (``out`` must not alias ``a`` or ``b``)."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@inline
def rotation_from_quaternion(qx, qy, qz, qw, R):
    """Rotation matrix of the unit quaternion ``(qx, qy, qz, qw)`` (scalar last)."""
    R[0, 0] = 1.0 - 2.0 * (qy * qy + qz * qz)
    R[0, 1] = 2.0 * (qx * qy - qz * qw)
    R[0, 2] = 2.0 * (qx * qz + qy * qw)
    R[1, 0] = 2.0 * (qx * qy + qz * qw)
    R[1, 1] = 1.0 - 2.0 * (qx * qx + qz * qz)
    R[1, 2] = 2.0 * (qy * qz - qx * qw)
    R[2, 0] = 2.0 * (qx * qz - qy * qw)
    R[2, 1] = 2.0 * (qy * qz + qx * qw)
    R[2, 2] = 1.0 - 2.0 * (qx * qx + qy * qy)


@inline
def compose(Ra, pa, Rb, pb, R, p):
    """``(R, p) = (Ra, pa) * (Rb, pb)``: ``R = Ra Rb``, ``p = pa + Ra pb``."""
    for r in range(3):
        p[r] = pa[r] + Ra[r, 0] * pb[0] + Ra[r, 1] * pb[1] + Ra[r, 2] * pb[2]
        for c in range(3):
            R[r, c] = Ra[r, 0] * Rb[0, c] + Ra[r, 1] * Rb[1, c] + Ra[r, 2] * Rb[2, c]


@inline
def motion_act(R, p, m, out):
    """Motion vector from child to parent coordinates: ``[R v + p x R w; R w]``."""
    w0 = R[0, 0] * m[3] + R[0, 1] * m[4] + R[0, 2] * m[5]
    w1 = R[1, 0] * m[3] + R[1, 1] * m[4] + R[1, 2] * m[5]
    w2 = R[2, 0] * m[3] + R[2, 1] * m[4] + R[2, 2] * m[5]
    v0 = R[0, 0] * m[0] + R[0, 1] * m[1] + R[0, 2] * m[2]
    v1 = R[1, 0] * m[0] + R[1, 1] * m[1] + R[1, 2] * m[2]
    v2 = R[2, 0] * m[0] + R[2, 1] * m[1] + R[2, 2] * m[2]
    out[0] = v0 + p[1] * w2 - p[2] * w1
    out[1] = v1 + p[2] * w0 - p[0] * w2
    out[2] = v2 + p[0] * w1 - p[1] * w0
    out[3] = w0
    out[4] = w1
    out[5] = w2


@inline
def motion_act_inv(R, p, m, out):
    """Motion vector from parent to child coordinates: ``[R^T (v - p x w); R^T w]``."""
    u0 = m[0] - (p[1] * m[5] - p[2] * m[4])
    u1 = m[1] - (p[2] * m[3] - p[0] * m[5])
    u2 = m[2] - (p[0] * m[4] - p[1] * m[3])
    w0, w1, w2 = m[3], m[4], m[5]
    out[0] = R[0, 0] * u0 + R[1, 0] * u1 + R[2, 0] * u2
    out[1] = R[0, 1] * u0 + R[1, 1] * u1 + R[2, 1] * u2
    out[2] = R[0, 2] * u0 + R[1, 2] * u1 + R[2, 2] * u2
    out[3] = R[0, 0] * w0 + R[1, 0] * w1 + R[2, 0] * w2
    out[4] = R[0, 1] * w0 + R[1, 1] * w1 + R[2, 1] * w2
    out[5] = R[0, 2] * w0 + R[1, 2] * w1 + R[2, 2] * w2


@inline
def force_act(R, p, f, out):
    """Force vector from child to parent coordinates: ``[R f; R n + p x R f]``."""
    f0 = R[0, 0] * f[0] + R[0, 1] * f[1] + R[0, 2] * f[2]
    f1 = R[1, 0] * f[0] + R[1, 1] * f[1] + R[1, 2] * f[2]
    f2 = R[2, 0] * f[0] + R[2, 1] * f[1] + R[2, 2] * f[2]
    n0 = R[0, 0] * f[3] + R[0, 1] * f[4] + R[0, 2] * f[5]
    n1 = R[1, 0] * f[3] + R[1, 1] * f[4] + R[1, 2] * f[5]
    n2 = R[2, 0] * f[3] + R[2, 1] * f[4] + R[2, 2] * f[5]
    out[0] = f0
    out[1] = f1
    out[2] = f2
    out[3] = n0 + p[1] * f2 - p[2] * f1
    out[4] = n1 + p[2] * f0 - p[0] * f2
    out[5] = n2 + p[0] * f1 - p[1] * f0


@inline
def force_act_inv(R, p, f, out):
    """Force vector from parent to child coordinates: ``[R^T f; R^T (n - p x f)]``."""
    u0 = f[3] - (p[1] * f[2] - p[2] * f[1])
    u1 = f[4] - (p[2] * f[0] - p[0] * f[2])
    u2 = f[5] - (p[0] * f[1] - p[1] * f[0])
    f0, f1, f2 = f[0], f[1], f[2]
    out[0] = R[0, 0] * f0 + R[1, 0] * f1 + R[2, 0] * f2
    out[1] = R[0, 1] * f0 + R[1, 1] * f1 + R[2, 1] * f2
    out[2] = R[0, 2] * f0 + R[1, 2] * f1 + R[2, 2] * f2
    out[3] = R[0, 0] * u0 + R[1, 0] * u1 + R[2, 0] * u2
    out[4] = R[0, 1] * u0 + R[1, 1] * u1 + R[2, 1] * u2
    out[5] = R[0, 2] * u0 + R[1, 2] * u1 + R[2, 2] * u2


@inline
def rotate6(R, x, out):
    """``out = [R x_lin; R x_ang]``: a motion or force vector turned by ``R`` (no translation)."""
    for o in (0, 3):
        x0, x1, x2 = x[o], x[o + 1], x[o + 2]
        for r in range(3):
            out[o + r] = R[r, 0] * x0 + R[r, 1] * x1 + R[r, 2] * x2


@inline
def shifted_motion(d, m):
    """A motion vector at a point moved to the point ``d`` from it, axes unchanged:
    ``[v - d x w; w]`` (:func:`motion_act_inv` with ``R = 1``), as a tuple of 6."""
    w0, w1, w2 = m[3], m[4], m[5]
    return (m[0] - (d[1] * w2 - d[2] * w1), m[1] - (d[2] * w0 - d[0] * w2), m[2] - (d[0] * w1 - d[1] * w0),
            w0, w1, w2)


@inline
def shift_motion(d, m, out):
    """``out =`` :func:`shifted_motion` ``(d, m)``."""
    out[0], out[1], out[2], out[3], out[4], out[5] = shifted_motion(d, m)


@inline
def unshifted_force(d, f):
    """A force vector about the point ``d`` moved back about the first point, axes unchanged:
    ``[f; n + d x f]`` (:func:`force_act` with ``R = 1``), as a tuple of 6."""
    f0, f1, f2 = f[0], f[1], f[2]
    return (f0, f1, f2, f[3] + d[1] * f2 - d[2] * f1, f[4] + d[2] * f0 - d[0] * f2, f[5] + d[0] * f1 - d[1] * f0)


@inline
def unshift_force(d, f, out):
    """``out =`` :func:`unshifted_force` ``(d, f)``."""
    out[0], out[1], out[2], out[3], out[4], out[5] = unshifted_force(d, f)


@inline
def motion_cross(m, n, out):
    """Spatial cross product of motions, ``out = m x n = [w x v' + v x w'; w x w']``."""
    v0, v1, v2, w0, w1, w2 = m[0], m[1], m[2], m[3], m[4], m[5]
    out[0] = w1 * n[2] - w2 * n[1] + v1 * n[5] - v2 * n[4]
    out[1] = w2 * n[0] - w0 * n[2] + v2 * n[3] - v0 * n[5]
    out[2] = w0 * n[1] - w1 * n[0] + v0 * n[4] - v1 * n[3]
    out[3] = w1 * n[5] - w2 * n[4]
    out[4] = w2 * n[3] - w0 * n[5]
    out[5] = w0 * n[4] - w1 * n[3]


@inline
def cross_into(a0, a1, a2, b0, b1, b2, out, o):
    """``out[o:o + 3] = a x b``."""
    out[o] = a1 * b2 - a2 * b1
    out[o + 1] = a2 * b0 - a0 * b2
    out[o + 2] = a0 * b1 - a1 * b0


@inline
def cross_unit(x0, x1, x2, j, s, out, o):
    """``out[o:o + 3] = x x (s e_j)`` for the unit vector ``e_j`` (j = 0, 1, 2)."""
    if j == 0:
        out[o], out[o + 1], out[o + 2] = 0.0, x2 * s, -x1 * s
    elif j == 1:
        out[o], out[o + 1], out[o + 2] = -x2 * s, 0.0, x0 * s
    else:
        out[o], out[o + 1], out[o + 2] = x1 * s, -x0 * s, 0.0


@inline
def motion_cross_unit(m, r, s, out):
    """``out = m x (s e_r)``: :func:`motion_cross` with a multiple of the unit motion ``e_r``
    (``r`` < 3: a translation, else a rotation about axis ``r - 3``)."""
    if r < 3:
        cross_unit(m[3], m[4], m[5], r, s, out, 0)
        out[3], out[4], out[5] = 0.0, 0.0, 0.0
    else:
        cross_unit(m[0], m[1], m[2], r - 3, s, out, 0)
        cross_unit(m[3], m[4], m[5], r - 3, s, out, 3)


@inline
def force_cross(m, f, out):
    """Dual cross product, ``out = m x* f = [w x f; w x n + v x f]``."""
    v0, v1, v2, w0, w1, w2 = m[0], m[1], m[2], m[3], m[4], m[5]
    out[0] = w1 * f[2] - w2 * f[1]
    out[1] = w2 * f[0] - w0 * f[2]
    out[2] = w0 * f[1] - w1 * f[0]
    out[3] = w1 * f[5] - w2 * f[4] + v1 * f[2] - v2 * f[1]
    out[4] = w2 * f[3] - w0 * f[5] + v2 * f[0] - v0 * f[2]
    out[5] = w0 * f[4] - w1 * f[3] + v0 * f[1] - v1 * f[0]


@inline
def momentum(theta, m):
    """Momentum of a motion, ``I m``, as a tuple ``(f0, f1, f2, n0, n1, n2)``, with ``I``
    given by its 10 parameters (an array or a tuple):
    ``[f; n] = [mass v - h x w; I_o w + h x v]``.
    """
    mass, hx, hy, hz = theta[0], theta[1], theta[2], theta[3]
    ixx, ixy, iyy, ixz, iyz, izz = theta[4], theta[5], theta[6], theta[7], theta[8], theta[9]
    v0, v1, v2, w0, w1, w2 = m[0], m[1], m[2], m[3], m[4], m[5]
    return (mass * v0 - (hy * w2 - hz * w1),
            mass * v1 - (hz * w0 - hx * w2),
            mass * v2 - (hx * w1 - hy * w0),
            ixx * w0 + ixy * w1 + ixz * w2 + (hy * v2 - hz * v1),
            ixy * w0 + iyy * w1 + iyz * w2 + (hz * v0 - hx * v2),
            ixz * w0 + iyz * w1 + izz * w2 + (hx * v1 - hy * v0))


@inline
def inertia_mul(theta, m, out):
    """``out = I m`` (see :func:`momentum`)."""
    out[0], out[1], out[2], out[3], out[4], out[5] = momentum(theta, m)


@inline
def inertia_rotated(R, theta):
    """Inertial parameters of a body turned by the rotation ``R`` about the frame origin,
    as a tuple of 10: ``h' = R h``, ``I' = R I R^T``."""
    mass = theta[0]
    h0, h1, h2 = theta[1], theta[2], theta[3]
    ixx, ixy, iyy, ixz, iyz, izz = theta[4], theta[5], theta[6], theta[7], theta[8], theta[9]
    # A = I R^T, then R A
    a00 = ixx * R[0, 0] + ixy * R[0, 1] + ixz * R[0, 2]
    a01 = ixx * R[1, 0] + ixy * R[1, 1] + ixz * R[1, 2]
    a02 = ixx * R[2, 0] + ixy * R[2, 1] + ixz * R[2, 2]
    a10 = ixy * R[0, 0] + iyy * R[0, 1] + iyz * R[0, 2]
    a11 = ixy * R[1, 0] + iyy * R[1, 1] + iyz * R[1, 2]
    a12 = ixy * R[2, 0] + iyy * R[2, 1] + iyz * R[2, 2]
    a20 = ixz * R[0, 0] + iyz * R[0, 1] + izz * R[0, 2]
    a21 = ixz * R[1, 0] + iyz * R[1, 1] + izz * R[1, 2]
    a22 = ixz * R[2, 0] + iyz * R[2, 1] + izz * R[2, 2]
    return (mass,
            R[0, 0] * h0 + R[0, 1] * h1 + R[0, 2] * h2,
            R[1, 0] * h0 + R[1, 1] * h1 + R[1, 2] * h2,
            R[2, 0] * h0 + R[2, 1] * h1 + R[2, 2] * h2,
            R[0, 0] * a00 + R[0, 1] * a10 + R[0, 2] * a20,
            R[0, 0] * a01 + R[0, 1] * a11 + R[0, 2] * a21,
            R[1, 0] * a01 + R[1, 1] * a11 + R[1, 2] * a21,
            R[0, 0] * a02 + R[0, 1] * a12 + R[0, 2] * a22,
            R[1, 0] * a02 + R[1, 1] * a12 + R[1, 2] * a22,
            R[2, 0] * a02 + R[2, 1] * a12 + R[2, 2] * a22)


@inline
def inertia_act(R, p, theta, out):
    """Inertial parameters of a body expressed in the parent frame of placement ``(R, p)``.

    ``h' = R h + m p``;
    ``I' = R I R^T - p h_r^T - h_r p^T + 2 (p . h_r) 1 - m p p^T + m |p|^2 1`` with
    ``h_r = R h`` (parallel-axis theorem without dividing by the mass).
    """
    mass, hr0, hr1, hr2, j00, j01, j11, j02, j12, j22 = inertia_rotated(R, theta)
    p0, p1, p2 = p[0], p[1], p[2]
    ph = p0 * hr0 + p1 * hr1 + p2 * hr2
    pp = p0 * p0 + p1 * p1 + p2 * p2
    out[0] = mass
    out[1] = hr0 + mass * p0
    out[2] = hr1 + mass * p1
    out[3] = hr2 + mass * p2
    out[4] = j00 - 2.0 * p0 * hr0 + 2.0 * ph - mass * p0 * p0 + mass * pp
    out[5] = j01 - p0 * hr1 - hr0 * p1 - mass * p0 * p1
    out[6] = j11 - 2.0 * p1 * hr1 + 2.0 * ph - mass * p1 * p1 + mass * pp
    out[7] = j02 - p0 * hr2 - hr0 * p2 - mass * p0 * p2
    out[8] = j12 - p1 * hr2 - hr1 * p2 - mass * p1 * p2
    out[9] = j22 - 2.0 * p2 * hr2 + 2.0 * ph - mass * p2 * p2 + mass * pp


@inline
def inertia_matrix(theta, out, lower):
    """The 6 x 6 spatial inertia matrix ``[[m 1, -h x], [h x, I_o]]`` of 10 parameters (an
    array or a tuple); its upper triangle only unless ``lower`` is True."""
    mass, hx, hy, hz = theta[0], theta[1], theta[2], theta[3]
    # rows 0-2: [m 1, -[h]x]; rows 3-5: [[h]x, I_o]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3], out[0, 4], out[0, 5] = mass, 0.0, 0.0, 0.0, hz, -hy
    out[1, 1], out[1, 2], out[1, 3], out[1, 4], out[1, 5] = mass, 0.0, -hz, 0.0, hx
    out[2, 2], out[2, 3], out[2, 4], out[2, 5] = mass, hy, -hx, 0.0
    out[3, 3], out[3, 4], out[3, 5] = theta[4], theta[5], theta[7]
    out[4, 4], out[4, 5] = theta[6], theta[8]
    out[5, 5] = theta[9]
    if lower:
        mirror_upper(out)


@inline
def dot6(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]


@inline
def matvec6(A, x, out):
    for r in range(6):
        s = 0.0
        for c in range(6):
            s += A[r, c] * x[c]
        out[r] = s


@inline
def matTvec6(A, x, out):
    for r in range(6):
        s = 0.0
        for c in range(6):
            s += A[c, r] * x[c]
        out[r] = s


@inline
def congruence_to_parent(R, p, A, B, PB, out):
    """``out += X^T A X`` for a symmetric 6 x 6 ``A`` (an articulated inertia in the child
    frame), ``X`` the parent-to-child motion transform of ``(R, p)``.

    With ``A = [[A11, A12], [A12^T, A22]]``, ``Bij = R Aij R^T`` and ``P = [p]x``:
    ``X^T A X = [[B11, B12 - B11 P], [., B22 + P B12 + (P B12)^T - P B11 P]]`` (symmetric).
    ``B`` (3, 3, 3) and ``PB`` (3, 3) are workspaces.
    """
    for blk in range(3):
        o_r = 0 if blk < 2 else 3
        o_c = 0 if blk == 0 else 3
        # PB = A_blk R^T, then B[blk] = R PB
        for k in range(3):
            a0, a1, a2 = A[o_r + k, o_c], A[o_r + k, o_c + 1], A[o_r + k, o_c + 2]
            for c in range(3):
                PB[k, c] = a0 * R[c, 0] + a1 * R[c, 1] + a2 * R[c, 2]
        for r in range(3):
            for c in range(3):
                B[blk, r, c] = R[r, 0] * PB[0, c] + R[r, 1] * PB[1, c] + R[r, 2] * PB[2, c]
    p0, p1, p2 = p[0], p[1], p[2]
    # columns of B11 P: (B11 P)[:, c] = B11 [p]x e_c
    for r in range(3):
        b0, b1, b2 = B[0, r, 0], B[0, r, 1], B[0, r, 2]
        # row r of B11 P = row r of B11 times [p]x
        bp0 = b1 * p2 - b2 * p1
        bp1 = b2 * p0 - b0 * p2
        bp2 = b0 * p1 - b1 * p0
        out[r, 3] += B[1, r, 0] - bp0
        out[r, 4] += B[1, r, 1] - bp1
        out[r, 5] += B[1, r, 2] - bp2
        out[3, r] += B[1, r, 0] - bp0
        out[4, r] += B[1, r, 1] - bp1
        out[5, r] += B[1, r, 2] - bp2
        for c in range(3):
            out[r, c] += B[0, r, c]
    # PB = P B12; then P B11 P
    for c in range(3):
        x0, x1, x2 = B[1, 0, c], B[1, 1, c], B[1, 2, c]
        PB[0, c] = p1 * x2 - p2 * x1
        PB[1, c] = p2 * x0 - p0 * x2
        PB[2, c] = p0 * x1 - p1 * x0
    for r in range(3):
        # row r of (P B11): (P B11)[r, :] = (p x B11[:, c])_r
        q0 = p1 * B[0, 2, 0] - p2 * B[0, 1, 0] if r == 0 else (p2 * B[0, 0, 0] - p0 * B[0, 2, 0] if r == 1 else p0 * B[0, 1, 0] - p1 * B[0, 0, 0])
        q1 = p1 * B[0, 2, 1] - p2 * B[0, 1, 1] if r == 0 else (p2 * B[0, 0, 1] - p0 * B[0, 2, 1] if r == 1 else p0 * B[0, 1, 1] - p1 * B[0, 0, 1])
        q2 = p1 * B[0, 2, 2] - p2 * B[0, 1, 2] if r == 0 else (p2 * B[0, 0, 2] - p0 * B[0, 2, 2] if r == 1 else p0 * B[0, 1, 2] - p1 * B[0, 0, 2])
        # (P B11 P)[r, :] = row (q0, q1, q2) times [p]x
        pbp0 = q1 * p2 - q2 * p1
        pbp1 = q2 * p0 - q0 * p2
        pbp2 = q0 * p1 - q1 * p0
        out[3 + r, 3] += B[2, r, 0] + PB[r, 0] + PB[0, r] - pbp0
        out[3 + r, 4] += B[2, r, 1] + PB[r, 1] + PB[1, r] - pbp1
        out[3 + r, 5] += B[2, r, 2] + PB[r, 2] + PB[2, r] - pbp2


@inline
def upper_triangle(A):
    """The 21 entries of the upper triangle of a symmetric 6 x 6 ``A``, row by row:
    ``(A00, A01, ..., A05, A11, ..., A15, A22, ..., A55)``."""
    return (A[0, 0], A[0, 1], A[0, 2], A[0, 3], A[0, 4], A[0, 5], A[1, 1], A[1, 2], A[1, 3], A[1, 4], A[1, 5],
            A[2, 2], A[2, 3], A[2, 4], A[2, 5], A[3, 3], A[3, 4], A[3, 5], A[4, 4], A[4, 5], A[5, 5])


@inline
def mirror_upper(A):
    """Copy the upper triangle of the 6 x 6 ``A`` onto its lower one."""
    for r in range(1, 6):
        for c in range(r):
            A[r, c] = A[c, r]


@inline
def congruence_shift(d, a, out, lower):
    """``out += X^T A X`` for a symmetric 6 x 6 ``A`` at the point ``d``, given by its upper
    triangle ``a`` (:func:`upper_triangle`), and ``X`` the shift by ``d``
    (:func:`congruence_to_parent` with ``R = 1``). With ``P = [d]x``:
    ``X^T A X = [[A11, C], [C^T, A22 + (P A12)^T + P C]]``, ``C = A12 - A11 P``.
    Only the upper triangle of ``out`` is updated; with ``lower`` True its lower triangle is
    then copied from the upper one (so ``out`` reads as the full symmetric sum).

    Taking ``A`` as values lets a caller pass one it computes without storing it (the ABA's
    ``IA_i - U_i D_i^-1 U_i^T``)."""
    (a00, a01, a02, a03, a04, a05, a11, a12, a13, a14, a15, a22, a23, a24, a25, a33, a34, a35, a44, a45,
     a55) = a
    d0, d1, d2 = d[0], d[1], d[2]
    # C = A12 - A11 P: row r of A11 P is (row r of A11) x d
    c00 = a03 - (a01 * d2 - a02 * d1)
    c01 = a04 - (a02 * d0 - a00 * d2)
    c02 = a05 - (a00 * d1 - a01 * d0)
    c10 = a13 - (a11 * d2 - a12 * d1)
    c11 = a14 - (a12 * d0 - a01 * d2)
    c12 = a15 - (a01 * d1 - a11 * d0)
    c20 = a23 - (a12 * d2 - a22 * d1)
    c21 = a24 - (a22 * d0 - a02 * d2)
    c22 = a25 - (a02 * d1 - a12 * d0)
    # E = (P A12)^T + P C: column c of P Y is d x (column c of Y); (P A12)^T[r, c] = (P A12)[c, r]
    e00 = (d1 * a23 - d2 * a13) + (d1 * c20 - d2 * c10)
    e01 = (d2 * a03 - d0 * a23) + (d1 * c21 - d2 * c11)
    e02 = (d0 * a13 - d1 * a03) + (d1 * c22 - d2 * c12)
    e11 = (d2 * a04 - d0 * a24) + (d2 * c01 - d0 * c21)
    e12 = (d0 * a14 - d1 * a04) + (d2 * c02 - d0 * c22)
    e22 = (d0 * a15 - d1 * a05) + (d0 * c12 - d1 * c02)
    out[0, 0] += a00
    out[0, 1] += a01
    out[0, 2] += a02
    out[1, 1] += a11
    out[1, 2] += a12
    out[2, 2] += a22
    out[0, 3] += c00
    out[0, 4] += c01
    out[0, 5] += c02
    out[1, 3] += c10
    out[1, 4] += c11
    out[1, 5] += c12
    out[2, 3] += c20
    out[2, 4] += c21
    out[2, 5] += c22
    out[3, 3] += a33 + e00
    out[3, 4] += a34 + e01
    out[3, 5] += a35 + e02
    out[4, 4] += a44 + e11
    out[4, 5] += a45 + e12
    out[5, 5] += a55 + e22
    if lower:
        mirror_upper(out)


@inline
def motion_cross_matrix(m, out):
    """6 x 6 matrix of ``n -> m x n``."""
    for r in range(6):
        for c in range(6):
            out[r, c] = 0.0
    v0, v1, v2, w0, w1, w2 = m[0], m[1], m[2], m[3], m[4], m[5]
    # [w]x on both diagonal blocks, [v]x in the upper-right block
    for o in (0, 3):
        out[o + 0, o + 1] = -w2
        out[o + 0, o + 2] = w1
        out[o + 1, o + 0] = w2
        out[o + 1, o + 2] = -w0
        out[o + 2, o + 0] = -w1
        out[o + 2, o + 1] = w0
    out[0, 4] = -v2
    out[0, 5] = v1
    out[1, 3] = v2
    out[1, 5] = -v0
    out[2, 3] = -v1
    out[2, 4] = v0


@inline
def wrench_to_local(frame, R, p, f, out):
    """A wrench ``[force; torque]`` given in ``frame`` expressed in the body frame ``(R, p)``.

    ``frame`` 0: already local; 1: world axes, torque about the world origin;
    2: world axes, torque about the body origin.
    """
    if frame == 0:
        for k in range(6):
            out[k] = f[k]
    elif frame == 1:
        force_act_inv(R, p, f, out)
    else:
        for r in range(3):
            out[r] = R[0, r] * f[0] + R[1, r] * f[1] + R[2, r] * f[2]
            out[r + 3] = R[0, r] * f[3] + R[1, r] * f[4] + R[2, r] * f[5]


@inline
def wrench_to_aligned(frame, R, p, f, out):
    """A wrench ``[force; torque]`` given in ``frame`` (codes of :func:`wrench_to_local`)
    expressed with world axes about the origin of the body placed at ``(R, p)``."""
    if frame == 0:
        rotate6(R, f, out)
    elif frame == 1:
        out[0], out[1], out[2] = f[0], f[1], f[2]
        out[3] = f[3] - (p[1] * f[2] - p[2] * f[1])
        out[4] = f[4] - (p[2] * f[0] - p[0] * f[2])
        out[5] = f[5] - (p[0] * f[1] - p[1] * f[0])
    else:
        for k in range(6):
            out[k] = f[k]
