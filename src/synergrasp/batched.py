"""Batched grasp-force optimisation: one primal-dual interior-point method run on thousands
of GFO problems at once (docs/batched_solver.md).

Per problem (method.md §4), forces in N:

    minimise ||f_p + E y||_2   subject to, per contact i,
        n_i.f_i >= f_min,   ||f_i - (n_i.f_i) n_i|| <= mu n_i.f_i

With E orthonormal, ||f_p + E y||^2 = ||f_p - E a||^2 + ||y + a||^2 (a = E^T f_p), so the
solver minimises t subject to (t, y + a) in a second-order cone: a linear-objective SOCP
in x = (t, y), solved through the homogeneous self-dual embedding (infeasibility ends in a
certificate, not a time-out) with Nesterov-Todd scaling and Mehrotra's predictor-corrector.
Every array carries the batch on its last axis; every operation is element-wise over the
batch and reduces over small leading axes in a fixed order, so a problem gives the same
numbers alone or inside any batch, padded or not.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from synergrasp.force_optimisation import GFOParams, mechanics_for, solve_gfo, strict_internal_forces
from synergrasp.mechanics import Grasp, tangent_pairs

__all__ = [
    "BatchResult",
    "BatchSolution",
    "GFOBatch",
    "SolverSettings",
    "gfo_batch",
    "optimise_grasps",
    "set_id",
    "solve_batch",
    "solve_gfo_batch",
]

#: Problems per padded batch in `optimise_grasps` (bounds the memory whatever the study size).
DEFAULT_BATCH_SIZE = 4096

# Status codes of the interior-point iteration (BatchResult.code).
_RUNNING, _OPTIMAL, _INFEASIBLE, _UNSOLVED = 0, 1, 2, 3


@dataclass(frozen=True, kw_only=True)
class SolverSettings:
    """Tolerances of the batched interior-point method.

    tol: relative primal/dual residual and duality-gap tolerance of an optimal point, and the
        residual tolerance of an infeasibility certificate (dimensionless; the data are
        scaled so that max(||f_p||, f_min) = 1)
    reduced_tol: the same tests, applied when the iteration stalls (step below
        `stall_step`) or reaches `max_iter`; failing them the problem is 'not decided'
    max_iter: iteration cap; a problem not decided by then falls back to `solve_gfo`
    step_fraction: fraction of the step to the cone boundary taken each iteration
    stall_step: a step below this ends the iteration (judged with `reduced_tol`)
    refine: iterative-refinement steps on the full KKT system per solve (0: none; 1 lowers
        the fallback share slightly at about 20 % more time per iteration)
    """

    tol: float = 1e-8
    reduced_tol: float = 1e-6
    max_iter: int = 50
    step_fraction: float = 0.99
    stall_step: float = 1e-3
    refine: int = 0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tol) and 0 < self.tol < 1):
            raise ValueError(f"tol must be in (0, 1), got {self.tol}")
        if not (isinstance(self.max_iter, int) and self.max_iter > 0):
            raise ValueError(f"max_iter must be a positive int, got {self.max_iter!r}")
        if not (0 < self.step_fraction < 1):
            raise ValueError(f"step_fraction must be in (0, 1), got {self.step_fraction}")


@dataclass(frozen=True)
class GFOBatch:
    """B GFO problems padded to a common contact count m and basis size e, batch last.

    rows:    (m, 3, e, B) contact-frame rows [n.E_i; t1.E_i / mu; t2.E_i / mu], per N of y
    h:       (m, 3, B)    the same rows applied to f_p, N
    a:       (e, B)       E^T f_p, N
    r0:      (B,)         ||f_p - E a||, the part of f_p no internal force can cancel, N
    f_min:   (B,)         least normal force, N
    contact: (m, B)       True where the contact exists (padding contacts are masked out)
    """

    rows: NDArray
    h: NDArray
    a: NDArray
    r0: NDArray
    f_min: NDArray
    contact: NDArray

    @property
    def size(self) -> int:
        return int(self.a.shape[-1])


@dataclass(frozen=True)
class BatchResult:
    """Outcome of `solve_batch`, one entry per problem.

    code: 1 optimal, 2 infeasible (certificate), 3 not decided within the iteration cap
    y: (e, B) optimal internal-force coordinates, N (NaN unless optimal)
    t: (B,) optimal ||y + a||, N (NaN unless optimal)
    iterations: (B,) interior-point iterations
    """

    code: NDArray
    y: NDArray
    t: NDArray
    iterations: NDArray


# --------------------------------------------------------------------------- building


def gfo_batch(
    f_p: Sequence[NDArray],
    E: Sequence[NDArray],
    normals: Sequence[NDArray],
    mu: float | Sequence[float],
    f_min: float | Sequence[float],
    m_pad: int | None = None,
    e_pad: int | None = None,
) -> GFOBatch:
    """Pad and stack GFO problems (f_p (3m,), E (3m, e) orthonormal, normals (m, 3)).

    Absent contacts and basis columns of a problem are zero-padded at the end, so the
    padded problem has exactly the same iterates as the problem alone.
    """
    B = len(f_p)
    if not (len(E) == len(normals) == B):
        raise ValueError(f"f_p, E and normals must have the same length, got {B}, {len(E)}, {len(normals)}")
    mus = np.broadcast_to(np.asarray(mu, dtype=float), (B,))
    fmins = np.broadcast_to(np.asarray(f_min, dtype=float), (B,))
    if not np.all(np.isfinite(mus) & (mus > 0)):
        raise ValueError("mu must be finite and > 0")
    if not np.all(np.isfinite(fmins) & (fmins >= 0)):
        raise ValueError("f_min must be finite and >= 0 (N)")
    blocks = [_problem_block(f_p[k], E[k], normals[k], mus[k], fmins[k], k) for k in range(B)]
    m = max([b.m for b in blocks] + [1]) if m_pad is None else m_pad
    e = max([b.e for b in blocks] + [1]) if e_pad is None else e_pad
    if max([b.m for b in blocks] + [0]) > m or max([b.e for b in blocks] + [0]) > e:
        raise ValueError(f"m_pad={m_pad} / e_pad={e_pad} smaller than the largest problem")
    batch, _ = _stack(blocks, m, e)
    return batch


def _contact_frames(normals: NDArray, mu: float | NDArray) -> NDArray:
    """(m, 3, 3) rows [n; t1/mu; t2/mu]: the Coulomb cone is rows @ f_i in SOC(3)."""
    t1, t2 = tangent_pairs(normals)
    mu = np.asarray(mu, dtype=float)[..., None]
    return np.stack([normals, t1 / mu, t2 / mu], axis=1)


# --------------------------------------------------------------------------- cone algebra
# A second-order cone vector is stored with its components on axis 0: v[0] >= ||v[1:]||.


def _soc_det(v: NDArray) -> NDArray:
    """v^T J v = v0^2 - ||v1||^2, computed as a product to keep relative accuracy near the boundary."""
    r = np.sqrt(np.sum(v[1:] * v[1:], axis=0))
    return (v[0] - r) * (v[0] + r)


def _soc_nt(s: NDArray, z: NDArray):
    """Nesterov-Todd scaling point of SOC pairs (s, z) in the interior.

    Returns (w, beta) with W = beta [[w0, w1^T], [w1, I + w1 w1^T / (1 + w0)]], w^T J w = 1,
    so that W z = W^-1 s = lambda and (W^T W)^-1 = beta^-2 (2 (Jw)(Jw)^T - J).
    """
    sd = np.sqrt(_soc_det(s))
    zd = np.sqrt(_soc_det(z))
    sb = s / sd
    zb = z / zd
    gamma = np.sqrt(0.5 * (1.0 + np.sum(sb * zb, axis=0)))
    w = sb.copy()
    w[0] += zb[0]
    w[1:] -= zb[1:]
    w /= 2.0 * gamma
    beta = np.sqrt(sd / zd)
    return w, beta


def _soc_apply(w: NDArray, beta: NDArray, v: NDArray, inverse: bool = False) -> NDArray:
    """W v (or W^-1 v) for the NT scaling (w, beta) of `_soc_nt`."""
    sign = -1.0 if inverse else 1.0
    w1v1 = np.sum(w[1:] * v[1:], axis=0)
    out = np.empty_like(v)
    out[0] = w[0] * v[0] + sign * w1v1
    out[1:] = v[1:] + w[1:] * (sign * v[0] + w1v1 / (1.0 + w[0]))
    return out * (1.0 / beta if inverse else beta)


def _soc_prod(u: NDArray, v: NDArray) -> NDArray:
    """Jordan product u o v = (u^T v, u0 v1 + v0 u1)."""
    out = np.empty_like(u)
    out[0] = np.sum(u * v, axis=0)
    out[1:] = u[0] * v[1:] + v[0] * u[1:]
    return out


def _soc_div(lam: NDArray, w: NDArray) -> NDArray:
    """x with lam o x = w (lam in the interior)."""
    rho = _soc_det(lam)
    nu = np.sum(lam[1:] * w[1:], axis=0)
    out = np.empty_like(w)
    out[0] = (lam[0] * w[0] - nu) / rho
    out[1:] = ((nu / lam[0] - w[0]) / rho) * lam[1:] + w[1:] / lam[0]
    return out


def _soc_max_step(v: NDArray, d: NDArray) -> NDArray:
    """Largest alpha >= 0 with v + alpha d in the cone (inf if unbounded); v interior."""
    a = d[0] * d[0] - np.sum(d[1:] * d[1:], axis=0)
    b = v[0] * d[0] - np.sum(v[1:] * d[1:], axis=0)
    c = _soc_det(v)
    disc = b * b - a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        denom = -b + np.sqrt(np.maximum(disc, 0.0))
        step = np.where((disc >= 0) & (denom > 0), c / denom, np.inf)
    return step


def _lin_max_step(v: NDArray, d: NDArray) -> NDArray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(d < 0, -v / d, np.inf)


def _soc_hessian(w: NDArray, beta: NDArray) -> NDArray:
    """(W^T W)^-1 = beta^-2 (2 u u^T - J), u = J w, as a (d, d, ...) array."""
    u = w.copy()
    u[1:] = -u[1:]
    H = 2.0 * u[:, None] * u[None, :]
    d = w.shape[0]
    H[0, 0] -= 1.0
    idx = np.arange(1, d)
    H[idx, idx] += 1.0
    return H / (beta * beta)


# --------------------------------------------------------------------------- linear algebra


def _cholesky(M: NDArray) -> NDArray:
    """Lower Cholesky factor of the SPD matrices M (n, n, B), column by column, batch last."""
    n = M.shape[0]
    L = np.zeros_like(M)
    for j in range(n):
        col = M[j:, j] - np.sum(L[j:, :j] * L[j, :j][None], axis=1) if j else M[j:, j].copy()
        d = np.sqrt(np.maximum(col[0], 1e-300))
        L[j, j] = d
        L[j + 1:, j] = col[1:] / d
    return L


def _cho_solve(L: NDArray, b: NDArray) -> NDArray:
    """Solve L L^T x = b for L (n, n, B), b (n, B)."""
    n = L.shape[0]
    u = np.empty_like(b)
    for i in range(n):
        acc = b[i] - np.sum(L[i, :i] * u[:i], axis=0) if i else b[i]
        u[i] = acc / L[i, i]
    x = np.empty_like(b)
    for i in range(n - 1, -1, -1):
        acc = u[i] - np.sum(L[i + 1:, i] * x[i + 1:], axis=0) if i < n - 1 else u[i]
        x[i] = acc / L[i, i]
    return x


# --------------------------------------------------------------------------- the solver


class _Cones:
    """Cone variables of a batch: per contact a linear slack (n.f - f_min) and a SOC(3)
    (the Coulomb cone), plus one SOC(e+1) for the objective epigraph (t, y + a)."""

    __slots__ = ("lin", "soc", "obj")

    def __init__(self, lin, soc, obj):
        self.lin, self.soc, self.obj = lin, soc, obj

    def copy(self):
        return _Cones(self.lin.copy(), self.soc.copy(), self.obj.copy())


def solve_batch(batch: GFOBatch, settings: SolverSettings = SolverSettings()) -> BatchResult:
    """Solve the padded batch with the homogeneous self-dual interior-point method.

    The data are scaled per problem by rho = max(||f_p||, f_min) (reported y, t in N).
    Verdicts: optimal when the scaled primal and dual residuals and the duality gap are below
    `tol`; infeasible when the dual iterate is a Farkas certificate (h^T z < 0 and
    ||G^T z|| <= tol |h^T z|); otherwise 'not decided' after `max_iter` iterations.
    """
    with np.errstate(all="ignore"):  # a breakdown shows as a non-finite iterate: 'not decided'
        return _solve_batch(batch, settings)


def _solve_batch(batch: GFOBatch, settings: SolverSettings) -> BatchResult:
    D, mask = batch.rows, batch.contact
    m, _, e, B = D.shape
    cm = mask.astype(float)
    # Scale so that the forces are O(1): the iteration then starts well centred.
    fp_norm = np.sqrt(batch.r0 * batch.r0 + np.sum(batch.a * batch.a, axis=0))
    rho = np.maximum(fp_norm, np.maximum(batch.f_min, 1e-12))
    h_soc = np.ascontiguousarray(np.where(mask, batch.h.transpose(1, 0, 2) / rho, 0.0))  # (3, m, B), components first
    h_lin = np.where(mask, (batch.h[:, 0] - batch.f_min) / rho, 0.0)
    a = batch.a / rho
    h_obj = np.concatenate([np.zeros((1, B)), (batch.r0 / rho)[None], a], axis=0)
    h_norm = np.maximum(1.0, np.sqrt(np.sum(h_lin * h_lin, axis=0) + np.sum(np.sum(h_soc * h_soc, axis=0), axis=0)
                                     + np.sum(a * a, axis=0)))
    n_deg = 2.0 * np.sum(cm, axis=0) + 1.0  # barrier degree: m linear + m SOC(3) + 1 objective cone

    # G x for x = (t, y): linear rows -D0 y, SOC rows -D y, objective rows -(t, 0, y):
    # the objective cone is (t, r0, y + a), so t is ||f|| / rho itself.
    def G_mul(x):
        Dy = np.einsum("mrjb,jb->rmb", D, x[1:])
        obj = np.zeros((x.shape[0] + 1, x.shape[1]))
        obj[0] = -x[0]
        obj[2:] = -x[1:]
        np.negative(Dy, out=Dy)
        return _Cones(Dy[0], Dy, obj)

    def GT_mul(zc: _Cones):
        zz = zc.soc.copy()
        zz[0] += zc.lin
        zz *= cm
        out = -np.delete(zc.obj, 1, axis=0)
        out[1:] -= np.einsum("mrjb,rmb->jb", D, zz)
        return out

    # Initial point of the embedding: x = 0, s = z = identity of the cone, tau = kappa = 1.
    x = np.zeros((e + 1, B))
    ident = _Cones(np.ones((m, B)), np.zeros((3, m, B)), np.zeros((e + 2, B)))
    ident.soc[0] = 1.0
    ident.obj[0] = 1.0
    s, z = ident.copy(), ident.copy()
    tau = np.ones(B)
    kappa = np.ones(B)
    code = np.zeros(B, dtype=np.int8)
    iters = np.zeros(B, dtype=np.int32)
    y_out = np.full((e, B), np.nan)
    t_out = np.full(B, np.nan)
    active = np.arange(B)
    tol = settings.tol
    stalled = np.zeros(B, dtype=bool)

    def take(c: _Cones, idx):
        return _Cones(c.lin[:, idx], c.soc[:, :, idx], c.obj[:, idx])

    for it in range(settings.max_iter + 1):
        Gx = G_mul(x)
        GTz = GT_mul(z)
        r_x = GTz.copy()
        r_x[0] += tau
        r_z = _Cones(Gx.lin + s.lin - h_lin * tau, Gx.soc + s.soc - h_soc * tau, Gx.obj + s.obj - h_obj * tau)
        r_z.lin *= cm
        r_z.soc *= cm
        hz = np.sum(h_lin * z.lin * cm, axis=0) + np.sum(np.sum(h_soc * z.soc, axis=0) * cm, axis=0) \
            + np.sum(h_obj * z.obj, axis=0)
        r_tau = kappa + x[0] + hz
        sz = np.sum((s.lin * z.lin + np.sum(s.soc * z.soc, axis=0)) * cm, axis=0) + np.sum(s.obj * z.obj, axis=0)
        mu = (sz + tau * kappa) / (n_deg + 1.0)

        # Stopping tests on the de-homogenised point.
        pres = np.sqrt(np.sum(r_z.lin ** 2, axis=0) + np.sum(np.sum(r_z.soc ** 2, axis=0), axis=0)
                       + np.sum(r_z.obj ** 2, axis=0)) / tau / h_norm
        dres = np.sqrt(np.sum(r_x ** 2, axis=0)) / tau
        pcost = x[0] / tau
        gap = sz / (tau * tau)
        gtz_norm = np.sqrt(np.sum(GTz ** 2, axis=0))

        def verdicts(eps):
            opt = (pres <= eps) & (dres <= eps) & ((gap <= eps) | (gap <= eps * np.abs(pcost)))
            return opt, ~opt & (hz < 0) & (gtz_norm <= eps * -hz)

        optimal, infeasible = verdicts(tol)
        near_opt, near_inf = verdicts(settings.reduced_tol)
        last = (it == settings.max_iter) | stalled
        optimal |= last & near_opt
        infeasible |= last & ~optimal & near_inf
        bad = ~(np.isfinite(mu) & np.isfinite(tau) & (tau > 0))
        done = optimal | infeasible | bad | last
        if np.any(done):
            ids = active[done]
            code[ids] = np.where(optimal[done], _OPTIMAL, np.where(infeasible[done], _INFEASIBLE, _UNSOLVED))
            iters[ids] = it
            opt = done & optimal
            y_out[:, active[opt]] = x[1:, opt] / tau[opt] * rho[opt]
            t_out[active[opt]] = x[0, opt] / tau[opt] * rho[opt]
            keep = ~done
            if not np.any(keep):
                break
            active = active[keep]
            D, cm, mask = D[..., keep], cm[:, keep], mask[:, keep]
            h_lin, h_soc, h_obj, h_norm = h_lin[:, keep], h_soc[..., keep], h_obj[:, keep], h_norm[keep]
            n_deg, rho, stalled = n_deg[keep], rho[keep], stalled[keep]
            x, tau, kappa, mu = x[:, keep], tau[keep], kappa[keep], mu[keep]
            s, z = take(s, keep), take(z, keep)
            r_x, r_tau = r_x[:, keep], r_tau[keep]
            r_z = take(r_z, keep)

        # Nesterov-Todd scaling and the normal matrix M = G^T (W^T W)^-1 G, (e+1, e+1).
        w_lin = np.where(cm > 0, z.lin / s.lin, 0.0)  # (W^T W)^-1 of the linear cone
        s_over_z = np.where(cm > 0, s.lin / z.lin, 0.0)
        lam_lin = np.sqrt(s.lin * z.lin)
        w_soc, b_soc = _soc_nt(s.soc, z.soc)
        w_obj, b_obj = _soc_nt(s.obj, z.obj)
        lam_soc = _soc_apply(w_soc, b_soc, z.soc)
        lam_obj = _soc_apply(w_obj, b_obj, z.obj)
        H_soc = _soc_hessian(w_soc, b_soc) * cm  # (3, 3, m, B)
        H_con = H_soc.copy()  # a contact's linear row is the first row of its cone rows
        H_con[0, 0] += w_lin
        H_obj = _soc_hessian(w_obj, b_obj)
        T = np.einsum("rkmb,mkjb->mrjb", H_con, D)
        M = np.delete(np.delete(H_obj, 1, axis=0), 1, axis=1)
        M[1:, 1:] += np.einsum("mrib,mrjb->ijb", D, T)
        L = _cholesky(M)

        def H_mul(v: _Cones) -> _Cones:
            # The same H matrices as in M: a closed form (2 u u^T - J) v rounds differently and,
            # without refinement, the mismatch with M costs accuracy near the optimum.
            return _Cones(w_lin * v.lin, np.einsum("rkmb,kmb->rmb", H_soc, v.soc), np.einsum("rkb,kb->rb", H_obj, v.obj))

        def V_mul(v: _Cones) -> _Cones:
            """W^T W v through the factors (more accurate than inverting H)."""
            return _Cones(s_over_z * v.lin,
                          _soc_apply(w_soc, b_soc, _soc_apply(w_soc, b_soc, v.soc)) * cm,
                          _soc_apply(w_obj, b_obj, _soc_apply(w_obj, b_obj, v.obj)))

        def reduced(bx, bz: _Cones):
            dx = _cho_solve(L, bx + GT_mul(H_mul(bz)))
            Gd = G_mul(dx)
            return dx, H_mul(_Cones(Gd.lin - bz.lin, Gd.soc - bz.soc, Gd.obj - bz.obj))

        def solve_kkt(bx, bz: _Cones):
            """[0 G^T; G -W^T W] [dx; dz] = [bx; bz], with iterative refinement on the full system."""
            dx, dz = reduced(bx, bz)
            for _ in range(settings.refine):
                Gd, Vz = G_mul(dx), V_mul(dz)
                rx = bx - GT_mul(dz)
                rz = _Cones(bz.lin - Gd.lin + Vz.lin, bz.soc - Gd.soc + Vz.soc, bz.obj - Gd.obj + Vz.obj)
                rz.lin *= cm
                rz.soc *= cm
                ex, ez = reduced(rx, rz)
                dx = dx + ex
                dz = _Cones(dz.lin + ez.lin, dz.soc + ez.soc, dz.obj + ez.obj)
            return dx, dz

        c_vec = np.zeros_like(x)
        c_vec[0] = 1.0
        x1, z1 = solve_kkt(-c_vec, _Cones(h_lin, h_soc, h_obj))
        cx1_hz1 = x1[0] + np.sum(h_lin * z1.lin * cm, axis=0) + np.sum(np.sum(h_soc * z1.soc, axis=0) * cm, axis=0) \
            + np.sum(h_obj * z1.obj, axis=0)

        def direction(sigma, ds_lin, ds_soc, ds_obj, d_kappa):
            """Newton direction for the complementarity right-hand sides (lambda \\ d_s form)."""
            # W^T (lambda \ d_s) per cone
            q_lin = np.sqrt(s.lin / np.where(cm > 0, z.lin, 1.0)) * (ds_lin / lam_lin)
            q_soc = _soc_apply(w_soc, b_soc, _soc_div(lam_soc, ds_soc))
            q_obj = _soc_apply(w_obj, b_obj, _soc_div(lam_obj, ds_obj))
            f = 1.0 - sigma
            bx = -f * r_x
            bz = _Cones(-f * r_z.lin + q_lin, -f * r_z.soc + q_soc, -f * r_z.obj + q_obj)
            x2, z2 = solve_kkt(bx, bz)
            cx2_hz2 = x2[0] + np.sum(h_lin * z2.lin * cm, axis=0) + np.sum(np.sum(h_soc * z2.soc, axis=0) * cm, axis=0) \
                + np.sum(h_obj * z2.obj, axis=0)
            dtau = (d_kappa / tau - f * r_tau - cx2_hz2) / (cx1_hz1 - kappa / tau)
            dx = x2 + dtau * x1
            dz = _Cones(z2.lin + dtau * z1.lin, z2.soc + dtau * z1.soc, z2.obj + dtau * z1.obj)
            dkappa = -(d_kappa + kappa * dtau) / tau
            # ds from the primal row G dx + ds - h dtau = -(1 - sigma) r_z: it keeps the primal
            # residual exact where W^T W is badly conditioned near the optimum.
            Gdx = G_mul(dx)
            ds_l = -f * r_z.lin - Gdx.lin + h_lin * dtau
            ds_s = -f * r_z.soc - Gdx.soc + h_soc * dtau
            ds_o = -f * r_z.obj - Gdx.obj + h_obj * dtau
            dz.lin *= cm
            dz.soc *= cm
            ds_l *= cm
            ds_s *= cm
            ds = _Cones(ds_l, ds_s, ds_o)
            return dx, dz, ds, dtau, dkappa

        def max_step(dz, ds, dtau, dkappa):
            inf = np.inf
            st = np.minimum(_lin_max_step(s.lin, ds.lin), _lin_max_step(z.lin, dz.lin))
            st = np.minimum(st, np.minimum(_soc_max_step(s.soc, ds.soc), _soc_max_step(z.soc, dz.soc)))
            st = np.where(cm > 0, st, inf).min(axis=0)
            st = np.minimum(st, np.minimum(_soc_max_step(s.obj, ds.obj), _soc_max_step(z.obj, dz.obj)))
            st = np.minimum(st, np.minimum(_lin_max_step(tau, dtau), _lin_max_step(kappa, dkappa)))
            return st

        # Predictor (affine scaling): d_s = lambda o lambda, d_kappa = tau kappa.
        lam_soc_sq = _soc_prod(lam_soc, lam_soc)
        lam_obj_sq = _soc_prod(lam_obj, lam_obj)
        dx_a, dz_a, ds_a, dtau_a, dkappa_a = direction(0.0, lam_lin * lam_lin, lam_soc_sq, lam_obj_sq, tau * kappa)
        alpha_a = np.minimum(1.0, max_step(dz_a, ds_a, dtau_a, dkappa_a))
        sigma = np.clip((1.0 - alpha_a) ** 3, 0.0, 1.0)
        sm = sigma * mu

        # Corrector: Mehrotra's second-order term (W^-T ds_a) o (W dz_a) and centring sigma mu.
        Wi_ds_l = np.sqrt(np.where(cm > 0, z.lin / np.where(cm > 0, s.lin, 1.0), 0.0)) * ds_a.lin
        W_dz_l = np.sqrt(np.where(cm > 0, s.lin / np.where(cm > 0, z.lin, 1.0), 0.0)) * dz_a.lin
        d_lin = lam_lin * lam_lin + Wi_ds_l * W_dz_l - sm
        corr_soc = _soc_prod(_soc_apply(w_soc, b_soc, ds_a.soc, inverse=True), _soc_apply(w_soc, b_soc, dz_a.soc))
        d_soc = lam_soc_sq + corr_soc
        d_soc[0] -= sm
        corr_obj = _soc_prod(_soc_apply(w_obj, b_obj, ds_a.obj, inverse=True), _soc_apply(w_obj, b_obj, dz_a.obj))
        d_obj = lam_obj_sq + corr_obj
        d_obj[0] -= sm
        d_kap = tau * kappa + dtau_a * dkappa_a - sm
        dx, dz, ds, dtau, dkappa = direction(sigma, d_lin, d_soc, d_obj, d_kap)
        alpha = np.minimum(1.0, settings.step_fraction * max_step(dz, ds, dtau, dkappa))

        # A vanishing step near the optimum means the normal equations have run out of
        # accuracy: keep the current point and judge it with the reduced tolerance.
        stalled = alpha < settings.stall_step
        alpha = np.where(stalled, 0.0, alpha)
        x = x + alpha * dx
        s = _Cones(s.lin + alpha * ds.lin, s.soc + alpha * ds.soc, s.obj + alpha * ds.obj)
        z = _Cones(z.lin + alpha * dz.lin, z.soc + alpha * dz.soc, z.obj + alpha * dz.obj)
        tau = tau + alpha * dtau
        kappa = kappa + alpha * dkappa

    return BatchResult(code=code, y=y_out, t=t_out, iterations=iters)


# --------------------------------------------------------------------------- many problems


@dataclass(frozen=True)
class _Block:
    """Problems sharing a contact count m and padded basis size e (one pose, one set size)."""

    rows: NDArray     # (n, m, 3, e)
    h: NDArray        # (n, m, 3)
    a: NDArray        # (n, e)
    r0: NDArray       # (n,)
    f_min: NDArray    # (n,)
    index: NDArray    # (n,) position of each problem in the caller's order

    @property
    def m(self) -> int:
        return int(self.rows.shape[1])

    @property
    def e(self) -> int:
        return int(self.rows.shape[3])


@dataclass(frozen=True)
class BatchSolution:
    """Verdicts of many GFO problems, in the caller's order (columnar).

    status: 'force_closure' | 'infeasible' | 'numerical_failure'
    force_norm: optimal ||f||_2, N (NaN unless force closure)
    iterations: interior-point iterations (of the fallback solver where it was used)
    solver: 'batched' | 'clarabel_fallback'
    max_violation: worst constraint violation of the optimal forces, N (NaN unless force closure)
    """

    status: NDArray
    force_norm: NDArray
    iterations: NDArray
    solver: NDArray
    max_violation: NDArray


def _pieces(blocks: list[_Block], batch_size: int) -> list[list[_Block]]:
    """Consecutive runs of blocks (sorted by e, then m) of about `batch_size` problems each.

    Splitting never changes a problem's numbers (padding is exact), only the speed: runs
    stay within one e (unless still below batch_size / 4) so that padding costs little.
    """
    order = sorted(range(len(blocks)), key=lambda k: (blocks[k].e, blocks[k].m))
    runs: list[list[_Block]] = []
    current: list[_Block] = []
    size = 0
    for k in order:
        b = blocks[k]
        # A new e starts a new run unless the run is still small (padding e beats tiny batches).
        if current and (size + b.a.shape[0] > batch_size or (b.e != current[-1].e and size >= batch_size // 4)):
            runs.append(current)
            current, size = [], 0
        current.append(b)
        size += b.a.shape[0]
    if current:
        runs.append(current)
    return runs


def _stack(run: list[_Block], m: int | None = None, e: int | None = None) -> tuple[GFOBatch, NDArray]:
    """Zero-pad the blocks of a run to m contacts and e basis columns (default: the run's
    largest) and stack them batch-last; also return each problem's caller index."""
    B = sum(b.a.shape[0] for b in run)
    m = max(b.m for b in run) if m is None else m
    e = max(b.e for b in run) if e is None else e
    rows = np.zeros((m, 3, e, B))
    h = np.zeros((m, 3, B))
    a = np.zeros((e, B))
    contact = np.zeros((m, B), dtype=bool)
    r0 = np.concatenate([b.r0 for b in run])
    f_min = np.concatenate([b.f_min for b in run])
    index = np.concatenate([b.index for b in run])
    k = 0
    for b in run:
        n = b.a.shape[0]
        rows[:b.m, :, :b.e, k:k + n] = b.rows.transpose(1, 2, 3, 0)
        h[:b.m, :, k:k + n] = b.h.transpose(1, 2, 0)
        a[:b.e, k:k + n] = b.a.T
        contact[:b.m, k:k + n] = True
        k += n
    return GFOBatch(rows=rows, h=h, a=a, r0=r0, f_min=f_min, contact=contact), index


def _forces_check(batch: GFOBatch, y: NDArray, mu: NDArray) -> tuple[NDArray, NDArray]:
    """||f|| (N) and the worst constraint violation (N) of f = f_p + E y, from the batch rows."""
    frame = batch.h + np.einsum("mrjb,jb->mrb", batch.rows, np.nan_to_num(y))  # [n.f, t1.f/mu, t2.f/mu]
    fn = frame[:, 0]
    ft = mu * np.sqrt(frame[:, 1] ** 2 + frame[:, 2] ** 2)
    norm = np.sqrt(np.sum(np.where(batch.contact, fn * fn + ft * ft, 0.0), axis=0))
    viol = np.where(batch.contact, np.maximum(batch.f_min - fn, ft - mu * fn), -np.inf).max(axis=0)
    return norm, viol


def _solve_blocks(
    blocks: list[_Block],
    mu: NDArray,
    total: int,
    fallback_problem,
    settings: SolverSettings,
    batch_size: int,
) -> BatchSolution:
    """Solve every problem of `blocks` in padded batches; undecided ones go to `solve_gfo`."""
    from synergrasp.force_optimisation import ALMOST_SOLVED_TOL

    status = np.full(total, "numerical_failure", dtype=object)
    norm = np.full(total, np.nan)
    iters = np.zeros(total, dtype=np.int32)
    solver = np.full(total, "batched", dtype=object)
    viol = np.full(total, np.nan)
    for run in _pieces(blocks, batch_size):
        batch, index = _stack(run)
        res = solve_batch(batch, settings)
        fn, fv = _forces_check(batch, res.y, mu[index])
        ok = (res.code == _OPTIMAL) & (fv <= ALMOST_SOLVED_TOL * np.maximum(1.0, fn))
        status[index[ok]] = "force_closure"
        norm[index[ok]] = fn[ok]
        viol[index[ok]] = fv[ok]
        inf = res.code == _INFEASIBLE
        status[index[inf]] = "infeasible"
        iters[index] = res.iterations
        for k in index[~(ok | inf)]:
            r = fallback_problem(int(k))
            status[k], iters[k], solver[k] = r.status, r.iterations, "clarabel_fallback"
            norm[k] = r.force_norm
            viol[k] = r.max_violation if r.status == "force_closure" else np.nan
    return BatchSolution(status=status, force_norm=norm, iterations=iters, solver=solver, max_violation=viol)


def _problem_block(f_p, E, normals, mu, f_min, index) -> _Block:
    n = np.asarray(normals, dtype=float)
    m = n.shape[0]
    Em = np.asarray(E, dtype=float).reshape(3 * m, -1)
    fp = np.asarray(f_p, dtype=float).reshape(3 * m)
    frames = _contact_frames(n, mu)
    e = Em.shape[1]
    a = Em.T @ fp
    return _Block(
        rows=np.einsum("iab,ibk->iak", frames, Em.reshape(m, 3, e))[None],
        h=np.einsum("iab,ib->ia", frames, fp.reshape(m, 3))[None],
        a=a[None], r0=np.array([np.linalg.norm(fp - Em @ a)]), f_min=np.array([float(f_min)]),
        index=np.array([index]),
    )


def solve_gfo_batch(
    f_p: Sequence[NDArray],
    E: Sequence[NDArray],
    normals: Sequence[NDArray],
    mu: float | Sequence[float],
    f_min: float | Sequence[float],
    *,
    settings: SolverSettings = SolverSettings(),
    batch_size: int = DEFAULT_BATCH_SIZE,
    tol: float = 1e-8,
    max_iter: int = 200,
) -> BatchSolution:
    """Solve many GFO problems (f_p (3m,) N, E (3m, e) orthonormal, normals (m, 3)) at once.

    Problems the batched method does not decide (iteration cap, stall, or an optimal point
    violating a constraint by more than 1e-6 max(1 N, ||f||)) are solved by `solve_gfo`
    (tolerance `tol`, cap `max_iter`) and marked 'clarabel_fallback'. Problems with e = 0
    are judged directly by `solve_gfo` (f = f_p), as the per-problem path does.
    """
    B = len(f_p)
    if not (len(E) == len(normals) == B):
        raise ValueError(f"f_p, E and normals must have the same length, got {B}, {len(E)}, {len(normals)}")
    if not (isinstance(batch_size, int) and batch_size > 0):
        raise ValueError(f"batch_size must be a positive int, got {batch_size!r}")
    mus = np.array(np.broadcast_to(np.asarray(mu, dtype=float), (B,)))
    fmins = np.array(np.broadcast_to(np.asarray(f_min, dtype=float), (B,)))
    blocks = []
    direct = []
    for k in range(B):
        Ek = np.asarray(E[k], dtype=float)
        if Ek.ndim == 1:
            Ek = Ek[:, None]
        if Ek.shape[1] == 0:
            direct.append(k)
            continue
        blocks.append(_problem_block(f_p[k], Ek, normals[k], mus[k], fmins[k], k))

    def fallback(k: int):
        return solve_gfo(f_p[k], E[k], normals[k], mus[k], fmins[k], tol=tol, max_iter=max_iter)

    out = _solve_blocks(blocks, mus, B, fallback, settings, batch_size)
    for k in direct:
        r = fallback(k)
        out.status[k], out.force_norm[k], out.iterations[k] = r.status, r.force_norm, 0
        out.max_violation[k] = r.max_violation if r.status == "force_closure" else np.nan
    return out


def set_id(subset: Sequence[int]) -> str:
    """'1-2-3' for the 1-based synergy indices of a set (sorted)."""
    return "-".join(str(int(k)) for k in sorted(subset))


def _check_sets(sets: Sequence[tuple[int, ...]], k: int) -> list[NDArray]:
    out = []
    for s in sets:
        idx = np.asarray(sorted(int(v) for v in s), dtype=int)
        if idx.size == 0 or idx[0] < 1 or idx[-1] > k or np.unique(idx).size != idx.size:
            raise ValueError(f"sets: each set must hold distinct 1-based synergy indices in 1..{k}, got {tuple(s)!r}")
        out.append(idx - 1)
    return out


def optimise_grasps(
    grasps: Sequence[Grasp | None],
    synergies: NDArray,
    sets: Sequence[tuple[int, ...]],
    params: GFOParams,
    batch_size: int = DEFAULT_BATCH_SIZE,
    *,
    strict: bool = True,
    settings: SolverSettings = SolverSettings(),
) -> dict[str, NDArray]:
    """GFO verdict, optimal force and strict internal-force test for every (grasp, set).

    grasps: poses (None or no contacts: 'no_grasp'); synergies: (n, k) synergy matrix,
    rad per unit activation; sets: 1-based synergy indices. Mechanics once per pose; E_s by
    the rule of `internal_force_basis` (singular values above
    basis_rtol ||projector||_2 ||S_set||_2); both SOCPs (GFO and strict test) solved by the
    batched method, poses taken in chunks of about `batch_size` problems (bounded memory).
    strict=False skips the strict test (column all False).
    Returns columns (one row per (pose, set), pose-major): pose, set_id, n_synergies,
    status, force_closure, strict_internal, force_norm (N), e_s, rank_G, n_contacts,
    iterations, solver.
    """
    S = np.asarray(synergies, dtype=float)
    if S.ndim != 2:
        raise ValueError(f"synergies must be an (n, k) matrix, got shape {S.shape}")
    if not (isinstance(batch_size, int) and batch_size > 0):
        raise ValueError(f"batch_size must be a positive int, got {batch_size!r}")
    cols = _check_sets(sets, S.shape[1])
    n_sets, n_poses = len(cols), len(grasps)
    total = n_sets * n_poses
    out = {
        "pose": np.repeat(np.arange(n_poses, dtype=np.int32), n_sets),
        "set_id": np.array([set_id(c + 1) for c in cols] * n_poses, dtype=object),
        "n_synergies": np.tile(np.array([c.size for c in cols], dtype=np.int32), n_poses),
        "status": np.full(total, "no_grasp", dtype=object),
        "force_closure": np.zeros(total, dtype=bool),
        "strict_internal": np.zeros(total, dtype=bool),
        "force_norm": np.full(total, np.nan),
        "e_s": np.zeros(total, dtype=np.int32),
        "rank_G": np.zeros(total, dtype=np.int32),
        "n_contacts": np.zeros(total, dtype=np.int32),
        "iterations": np.zeros(total, dtype=np.int32),
        "solver": np.full(total, "batched", dtype=object),
    }
    if total == 0:
        return out
    set_norms = np.array([np.linalg.norm(S[:, c], 2) for c in cols])
    by_size: dict[int, list[int]] = {}
    for j, c in enumerate(cols):
        by_size.setdefault(c.size, []).append(j)
    mu_strict = params.mu * (1.0 - params.strict_shrink)
    per_chunk = max(1, 4 * batch_size // (n_sets * (2 if strict else 1)))  # several batches per chunk

    for start in range(0, n_poses, per_chunk):
        stop = min(n_poses, start + per_chunk)
        chunk = _Chunk(row0=start * n_sets, n_rows=(stop - start) * n_sets)
        for p in range(start, stop):
            grasp = grasps[p]
            if grasp is None or grasp.n_contacts == 0:
                continue
            rows0 = p * n_sets
            mech = mechanics_for(grasp, params)
            out["rank_G"][rows0:rows0 + n_sets] = mech.rank_G
            out["n_contacts"][rows0:rows0 + n_sets] = mech.n_contacts
            if mech.rank_G < 6 or mech.projector is None:
                out["status"][rows0:rows0 + n_sets] = "rank_deficient"
                continue
            _pose_blocks(chunk, mech, S, cols, by_size, set_norms, params, mu_strict, rows0, strict, out["e_s"])
        if chunk.bases:
            _solve_chunk(chunk, params, mu_strict, settings, batch_size, strict, out)
    out["force_closure"] = out["status"] == "force_closure"
    return out


@dataclass
class _Chunk:
    """Problems of consecutive poses; GFO problem of output row r has local index
    r - row0, its strict test r - row0 + n_rows."""

    row0: int
    n_rows: int
    blocks: list = None
    bases: dict = None     # output row -> (E (c, e_s), mechanics)

    def __post_init__(self) -> None:
        self.blocks, self.bases = [], {}


def _pose_blocks(chunk, mech, S, cols, by_size, set_norms, params, mu_strict, rows0, strict, out_e_s) -> None:
    """Blocks of one pose: per set size s, the bases of all its sets from one stacked SVD."""
    m = mech.n_contacts
    P = mech.projector
    scale_P = float(np.linalg.norm(P, 2)) if P.size else 0.0
    F_all = P @ S                                     # (c, k): one column per synergy
    frames = _contact_frames(mech.normals, params.mu)
    frames_strict = _contact_frames(mech.normals, mu_strict)
    fp = mech.f_p
    h = np.einsum("iab,ib->ia", frames, fp.reshape(m, 3))
    for size, js in by_size.items():
        F = np.stack([F_all[:, cols[j]] for j in js])  # (n, c, s)
        U, sv, _ = np.linalg.svd(F, full_matrices=False)
        rank = np.sum(sv > (params.basis_rtol * scale_P * set_norms[js])[:, None], axis=1)
        U = U * (np.arange(U.shape[2])[None, None, :] < rank[:, None, None])  # zero columns beyond e_s
        rows = np.asarray(js) + rows0
        out_e_s[rows] = rank
        for k, row in enumerate(rows):
            chunk.bases[int(row)] = (U[k, :, :rank[k]], mech)
        pos = rank > 0
        n = int(pos.sum())
        if n == 0:
            continue
        Up = U[pos]
        a = np.einsum("nck,c->nk", Up, fp)
        r0 = np.linalg.norm(fp[None] - np.einsum("nck,nk->nc", Up, a), axis=1)
        U4 = Up.reshape(n, m, 3, Up.shape[2])
        local = rows[pos] - chunk.row0
        chunk.blocks.append(_Block(rows=np.einsum("iab,nibk->niak", frames, U4), h=np.broadcast_to(h, (n, m, 3)),
                                   a=a, r0=r0, f_min=np.full(n, params.f_min), index=local))
        if strict:
            chunk.blocks.append(_Block(rows=np.einsum("iab,nibk->niak", frames_strict, U4), h=np.zeros((n, m, 3)),
                                       a=np.zeros_like(a), r0=np.zeros(n), f_min=np.ones(n), index=local + chunk.n_rows))


def _solve_chunk(chunk: _Chunk, params, mu_strict, settings, batch_size, strict, out) -> None:
    n = chunk.n_rows

    def fallback(k: int):
        E, mech = chunk.bases[chunk.row0 + k % n]
        if k < n:
            return solve_gfo(mech.f_p, E, mech.normals, params.mu, params.f_min, tol=params.tol,
                             max_iter=params.max_iter)
        return strict_internal_forces(E, mech.normals, params.mu, params.strict_shrink, tol=params.tol,
                                      max_iter=params.max_iter).result

    mu = np.empty(2 * n)
    mu[:n], mu[n:] = params.mu, mu_strict
    sol = _solve_blocks(chunk.blocks, mu, 2 * n, fallback, settings, batch_size)
    for row, (E, mech) in chunk.bases.items():
        k = row - chunk.row0
        if E.shape[1] == 0:  # f = f_p only: judged directly, as the per-problem path does
            r = solve_gfo(mech.f_p, E, mech.normals, params.mu, params.f_min, tol=params.tol)
            out["status"][row], out["force_norm"][row] = r.status, r.force_norm
            continue
        out["status"][row] = sol.status[k]
        out["force_norm"][row] = sol.force_norm[k]
        out["iterations"][row] = sol.iterations[k]
        out["solver"][row] = sol.solver[k]
        if strict:
            out["strict_internal"][row] = sol.status[k + n] == "force_closure"
