"""Cone algebra of the kernel: second-order cones (Nesterov-Todd scaling, Jordan product
and division, step to the boundary) and the step of a nonnegative coordinate. A cone is
addressed as (array, offset k, dimension d) in the flat layout of `layout`."""

from __future__ import annotations

import math

from synergrasp.optimisation.ipm.compiled import jit_inline

__all__ = ["lin_max_step", "soc_apply", "soc_det", "soc_div", "soc_hessian", "soc_max_step", "soc_nt", "soc_prod"]


@jit_inline
def soc_det(v, k, d):
    """v^T J v = v0^2 - ||v1||^2, as a product to keep relative accuracy near the boundary."""
    r = 0.0
    for i in range(k + 1, k + d):
        r += v[i] * v[i]
    r = math.sqrt(r)
    return (v[k] - r) * (v[k] + r)


@jit_inline
def soc_nt(s, z, w, k, d):
    """Nesterov-Todd scaling point of the interior pair (s, z): fills w (w^T J w = 1) and
    returns beta, with W z = W^-1 s = lambda and (W^T W)^-1 = beta^-2 (2 (Jw)(Jw)^T - J)."""
    sd = math.sqrt(soc_det(s, k, d))
    zd = math.sqrt(soc_det(z, k, d))
    dot = 0.0
    for i in range(k, k + d):
        dot += (s[i] / sd) * (z[i] / zd)
    gamma2 = 2.0 * math.sqrt(0.5 * (1.0 + dot))
    w[k] = (s[k] / sd + z[k] / zd) / gamma2
    for i in range(k + 1, k + d):
        w[i] = (s[i] / sd - z[i] / zd) / gamma2
    return math.sqrt(sd / zd)


@jit_inline
def soc_apply(w, beta, v, out, k, d, inverse):
    """out = W v (or W^-1 v) for the NT scaling (w, beta)."""
    sign = -1.0 if inverse else 1.0
    scale = 1.0 / beta if inverse else beta
    w1v1 = 0.0
    for i in range(k + 1, k + d):
        w1v1 += w[i] * v[i]
    c = sign * v[k] + w1v1 / (1.0 + w[k])
    out[k] = (w[k] * v[k] + sign * w1v1) * scale
    for i in range(k + 1, k + d):
        out[i] = (v[i] + w[i] * c) * scale


@jit_inline
def soc_hessian(w, beta, k, d, H, r0):
    """H[r0:r0 + d, :d] = (W^T W)^-1 = beta^-2 (2 u u^T - J), u = J w."""
    ib2 = 1.0 / (beta * beta)
    for i in range(d):
        ui = w[k + i] if i == 0 else -w[k + i]
        for j in range(d):
            uj = w[k + j] if j == 0 else -w[k + j]
            H[r0 + i, j] = 2.0 * ui * uj
        H[r0 + i, i] += -1.0 if i == 0 else 1.0
        for j in range(d):
            H[r0 + i, j] *= ib2


@jit_inline
def soc_prod(u, v, out, k, d):
    """Jordan product u o v = (u^T v, u0 v1 + v0 u1)."""
    acc = 0.0
    for i in range(k, k + d):
        acc += u[i] * v[i]
    for i in range(k + 1, k + d):
        out[i] = u[k] * v[i] + v[k] * u[i]
    out[k] = acc


@jit_inline
def soc_div(lam, w, out, k, d):
    """out = x with lam o x = w (lam in the interior)."""
    rho = soc_det(lam, k, d)
    nu = 0.0
    for i in range(k + 1, k + d):
        nu += lam[i] * w[i]
    c = (nu / lam[k] - w[k]) / rho
    out[k] = (lam[k] * w[k] - nu) / rho
    for i in range(k + 1, k + d):
        out[i] = c * lam[i] + w[i] / lam[k]


@jit_inline
def soc_max_step(v, dv, k, d):
    """Largest alpha >= 0 with v + alpha dv in the cone (inf if unbounded); v interior."""
    a = dv[k] * dv[k]
    b = v[k] * dv[k]
    for i in range(k + 1, k + d):
        a -= dv[i] * dv[i]
        b -= v[i] * dv[i]
    c = soc_det(v, k, d)
    disc = b * b - a * c
    denom = -b + math.sqrt(max(disc, 0.0))
    if disc >= 0.0 and denom > 0.0:
        return c / denom
    return math.inf


@jit_inline
def lin_max_step(v, d):
    return -v / d if d < 0.0 else math.inf
