"""Active-set polish of an interior-point iterate: guess which constraints are active at the
optimum from the iterate, solve the problem with those constraints as equalities exactly
(Newton on its KKT system), and accept the point only if it satisfies the optimality
conditions of the whole problem to the kernel's tolerance.

In the kernel's scaled units (`iteration.start`) the GFO is: minimise 1/2 ||y + a||^2 over
y subject to the linear rows h_k + A_k y >= 0 (k < L) and, per contact i, the Coulomb cone
u_i = h_c + D_i y in SOC(3) (c = L + 3i), A = -G on the constraint rows. The iteration
minimises t = ||(r0, y + a)|| instead; both have the same minimiser, and their Lagrange
multipliers differ by the factor t (those of the iteration are the dual iterate z / tau).

With the active linear rows and the active cones (u_i on the cone's boundary, u_i0 =
||(u_i1, u_i2)||) as equalities c(y) = 0 with Jacobian J, a Newton step solves
[H -J^T; J 0] [dy; lambda] = [-(y + a); -c], H = I + sum_i gamma_i D_it^T (I - n n^T) D_it /
||u_it|| (the cone constraints' curvature, gamma_i their multipliers, n = u_it / ||u_it||),
by the Schur complement J H^-1 J^T. Linear rows alone converge in one step; the cones in a
few. The point is accepted when every constraint holds to tol h_norm, every multiplier is
>= -tol t, and the stationarity residual ||y + a - J^T lambda|| and the complementarity
sum |lambda_k c_k| are <= tol t: the optimality test of `certificates.is_optimal` in the
units of the iteration's multipliers (lambda / t). A problem is convex, so such a point is
its optimum to that tolerance, whatever the iterate it came from; a wrong guess of the
active set fails the test and changes nothing.

Why: near a degenerate optimum the normal equations lose accuracy and the interior-point
step stalls a little short of the 1e-8 tests (the objective cone's scaling is then
badly conditioned); the polish does not use that scaling.
"""

from __future__ import annotations

import math

from synergrasp.optimisation.ipm.compiled import jit_call, jit_inline
from synergrasp.optimisation.ipm.linear_systems import cho_solve, cholesky

__all__ = ["polish"]

#: Newton steps of the polish at most (linear rows need one and a check; cones converge quadratically).
NEWTON_STEPS = 6


@jit_inline
def row(P, k, j):
    """Entry j of A_k, the homogeneous part of linear row k (A = -G): a contact's normal row
    (the first row of its Coulomb cone) for k < q, else a row of DL."""
    return P.D[k, 0, j] if k < P.q else P.DL[k - P.q, j]


@jit_inline
def cone_value(P, W, Q, i, y):
    """u = h_c + D_i y of cone i (c = L + 3i) into Q.u[0:3]; returns ||(u1, u2)||."""
    c = P.L + 3 * i
    for r in range(3):
        acc = W.h[c + r]
        for j in range(P.e):
            acc += P.D[i, r, j] * y[j]
        Q.u[r] = acc
    return math.sqrt(Q.u[1] * Q.u[1] + Q.u[2] * Q.u[2])


@jit_inline
def linearise(P, W, Q, n_act, y):
    """Rows of J (Q.J) and values c (Q.c) of the active constraints at y (Q.act: k < L a
    linear row, L + i cone i), and H (Q.H) with the cones' curvature for the multipliers
    Q.lam; returns False where a cone's tangential part vanishes (its gradient is undefined)."""
    e, H = P.e, Q.H
    for j in range(e):
        for l in range(e):
            H[j, l] = 1.0 if j == l else 0.0
    for a in range(n_act):
        k = Q.act[a]
        if k < P.L:
            acc = W.h[k]
            for j in range(e):
                Q.J[a, j] = row(P, k, j)
                acc += Q.J[a, j] * y[j]
            Q.c[a] = acc
            continue
        i = k - P.L
        ut = cone_value(P, W, Q, i, y)
        if not ut > 1e-12 * (1.0 + abs(Q.u[0])):
            return False
        n1, n2 = Q.u[1] / ut, Q.u[2] / ut
        Q.c[a] = Q.u[0] - ut
        curv = max(Q.lam[a], 0.0) / ut
        for j in range(e):
            Q.J[a, j] = P.D[i, 0, j] - n1 * P.D[i, 1, j] - n2 * P.D[i, 2, j]
            Q.v[j] = -n2 * P.D[i, 1, j] + n1 * P.D[i, 2, j]  # the tangential direction across n
        for j in range(e):
            for l in range(e):
                H[j, l] += curv * Q.v[j] * Q.v[l]
    return True


@jit_inline
def newton_step(P, W, Q, n_act, y):
    """One Newton step on the KKT system of the equality-constrained problem: y += dy and
    Q.lam = lambda. Returns ||dy||, or -1 if J H^-1 J^T is not positive definite (dependent
    active constraints: the guess is degenerate)."""
    e = P.e
    cholesky(Q.H, Q.R, e)
    for j in range(e):
        Q.g[j] = y[j] + W.h[P.L + 3 * P.q + 2 + j]
    cho_solve(Q.R, e, Q.g, Q.Hg)
    for a in range(n_act):  # column a of Y = H^-1 J^T
        for j in range(e):
            Q.v[j] = Q.J[a, j]
        cho_solve(Q.R, e, Q.v, Q.w)
        for j in range(e):
            Q.Y[j, a] = Q.w[j]
    scale = 0.0
    for a in range(n_act):
        acc = -Q.c[a]
        for j in range(e):
            acc += Q.J[a, j] * Q.Hg[j]
        Q.b[a] = acc
        for b in range(a + 1):
            acc = 0.0
            for j in range(e):
                acc += Q.J[a, j] * Q.Y[j, b]
            Q.S[a, b] = acc
        scale = max(scale, Q.S[a, a])
    cholesky(Q.S, Q.RS, n_act)
    for a in range(n_act):
        if not Q.RS[a, a] * Q.RS[a, a] > 1e-14 * scale:
            return -1.0
    cho_solve(Q.RS, n_act, Q.b, Q.lam)
    step = 0.0
    for j in range(e):
        acc = -Q.Hg[j]
        for a in range(n_act):
            acc += Q.Y[j, a] * Q.lam[a]
        y[j] += acc
        step += acc * acc
    return math.sqrt(step)


@jit_inline
def active_set(P, W, Q):
    """Q.act from the iterate (s, z): a linear row is active where its slack is below its
    multiplier, a cone where the slack's distance to the boundary is below the multiplier's
    size. Returns their number, -1 if more than e (then the guess cannot be solved as a
    square-or-less system)."""
    s, z = W.s, W.z
    n_act = 0
    for k in range(P.L):
        if s[k] < z[k]:
            if n_act == P.e:
                return -1
            Q.act[n_act] = k
            n_act += 1
    for i in range(P.q):
        c = P.L + 3 * i
        gap = s[c] - math.sqrt(s[c + 1] * s[c + 1] + s[c + 2] * s[c + 2])
        if gap < z[c]:
            if n_act == P.e:
                return -1
            Q.act[n_act] = P.L + i
            n_act += 1
    return n_act


@jit_inline
def accepted(P, W, Q, n_act, y, tol, h_norm):
    """The optimality test of the polished point (module docstring)."""
    e, h = P.e, W.h
    o = P.L + 3 * P.q
    t = h[o + 1] * h[o + 1]
    for j in range(e):
        Q.g[j] = y[j] + h[o + 2 + j]
        t += Q.g[j] * Q.g[j]
    t = max(math.sqrt(t), 1e-300)
    worst = 0.0  # the largest violation of any constraint
    for k in range(P.L):
        acc = h[k]
        for j in range(e):
            acc += row(P, k, j) * y[j]
        worst = max(worst, -acc)
    for i in range(P.q):
        ut = cone_value(P, W, Q, i, y)
        worst = max(worst, ut - Q.u[0])
    if not worst <= tol * h_norm:
        return False
    if not linearise(P, W, Q, n_act, y):
        return False
    gap = 0.0
    for a in range(n_act):
        if not Q.lam[a] >= -tol * t:
            return False
        gap += abs(Q.lam[a] * Q.c[a])
        for j in range(e):
            Q.g[j] -= Q.J[a, j] * Q.lam[a]
    res = 0.0
    for j in range(e):
        res += Q.g[j] * Q.g[j]
    return math.sqrt(res) <= tol * t and gap <= tol * t * max(1.0, t)


@jit_inline
def multipliers_plausible(Q, n_act, t):
    """False once a multiplier is clearly negative (the guess holds a constraint that the
    optimum leaves inactive; Newton does not repair that)."""
    for a in range(n_act):
        if Q.lam[a] < -1e-3 * abs(t):
            return False
    return True


@jit_inline
def same_as_last_failure(Q, n_act):
    if Q.last[0] != n_act:
        return False
    for a in range(n_act):
        if Q.last[1 + a] != Q.act[a]:
            return False
    return True


@jit_inline
def remember_failure(Q, n_act):
    Q.last[0] = n_act
    for a in range(n_act):
        Q.last[1 + a] = Q.act[a]


@jit_call
def polish(P, W, Q, tau, tol, h_norm, y):
    """Polish the iterate (W.x, W.s, W.z, tau) of `iteration.hsde`; True if the polished
    point passes the optimality test at `tol`, with y (scaled units) filled. Multipliers
    start from the dual iterate (t z / tau) and are updated by each Newton step. A guess that
    failed is remembered (Q.last; `iteration.hsde` clears it per problem)."""
    n_act = active_set(P, W, Q)
    if n_act <= 0:  # none active: the iteration's own test decides
        return False
    cones = Q.act[n_act - 1] >= P.L
    if not cones and same_as_last_failure(Q, n_act):
        return False  # linear rows only: the same guess gives the same point, whatever the start
    t = W.x[0] / tau
    for j in range(P.e):
        y[j] = W.x[1 + j] / tau
    for a in range(n_act):
        Q.lam[a] = t * W.z[P.L + 3 * (Q.act[a] - P.L)] / tau if Q.act[a] >= P.L else 0.0
    for _ in range(NEWTON_STEPS):
        if not linearise(P, W, Q, n_act, y):
            break
        step = newton_step(P, W, Q, n_act, y)
        if step < 0.0 or not multipliers_plausible(Q, n_act, t):
            break
        # linear rows only: the first step is exact; cones: the error after a step of
        # relative size 1e-7 is of order 1e-14
        if not cones or step <= 1e-7 * (1.0 + abs(t)):
            if accepted(P, W, Q, n_act, y, tol, h_norm):
                return True
            break
    remember_failure(Q, n_act)
    return False
