"""The compiled call per pose: every synergy set of one grasp (`solve_sets`): the set's
basis by one-sided Jacobi rotations (`set_bases`), its problem built into the pose's work
arrays (`build`), solved (`solve_one`: `hsde` and a refined second attempt) and its forces
checked, then the strict internal-force test on the same basis."""

from __future__ import annotations

import math

import numpy as np

from synergrasp.optimisation.ipm.compiled import jit_alloc, jit_call, jit_inline
from synergrasp.optimisation.ipm.iteration import hsde
from synergrasp.optimisation.ipm.layout import (
    INFEASIBLE,
    NOT_SOLVED,
    OPTIMAL,
    UNDECIDED,
    Problem,
    polish_workspace,
    workspace,
)

__all__ = ["set_bases", "solve_sets"]


@jit_alloc
def build(rows, lin, E, fp, e, mu, f_min, W):
    """The problem of cone rows (m, 3, 3) (`cone_rows`), linear rows lin (m, p, 3)
    (`ipm.solver.cone_data`: p = 0 for the circular cone, whose Coulomb cones are SOCs; a pyramid's
    [n; -a_1; ...] with the normal bound first, the kernel's nonnegative block in this
    order), basis E (3m, >= e; its first e columns) and f_p (3m,) N, its data written into W."""
    m, p = rows.shape[0], lin.shape[1]
    D, hv, a, DL, hl = W.D, W.hv, W.a, W.DL, W.hl
    for i in range(m):
        for r in range(p):
            k = i * p + r
            acc = 0.0
            for q in range(3):
                acc += lin[i, r, q] * fp[3 * i + q]
            hl[k] = acc - f_min if r == 0 else acc
            for j in range(e):
                acc = 0.0
                for q in range(3):
                    acc += lin[i, r, q] * E[3 * i + q, j]
                DL[k, j] = acc
    for i in range(m):
        for r in range(3):
            acc = 0.0
            for q in range(3):
                acc += rows[i, r, q] * fp[3 * i + q]
            hv[i, r] = acc
            for k in range(e):
                acc = 0.0
                for q in range(3):
                    acc += rows[i, r, q] * E[3 * i + q, k]
                D[i, r, k] = acc
    for k in range(e):
        a[k] = 0.0
    for c in range(3 * m):
        for k in range(e):
            a[k] += E[c, k] * fp[c]
    r0 = 0.0
    for c in range(3 * m):
        acc = fp[c]
        for k in range(e):
            acc -= E[c, k] * a[k]
        r0 += acc * acc
    q = m if p == 0 else 0
    return Problem(D, hv, a, math.sqrt(r0), mu, f_min, m, e, q, m * p, q + m * p, DL, hl)


@jit_inline
def attempt(P, W, Q, opt, refine, y):
    """`hsde`, then the force check of an optimal point: (code, ||f|| N, violation N, iterations).
    An optimal point whose forces violate a constraint by more than violation_tol max(1 N, ||f||)
    is 'not decided' (the rule of `solve_gfo` for reduced accuracy)."""
    code, it = hsde(P, W, Q, opt, refine, y)
    if code != OPTIMAL or opt.feasibility:  # a feasibility verdict is proved by `hsde` itself
        return code, math.nan, math.nan, it
    # f = f_p + E y in the contact frames: [n.f, t1.f/mu, t2.f/mu]
    D, hv, DL, hl, e = P.D, P.hv, P.DL, P.hl, P.e
    norm = 0.0
    viol = -math.inf
    for i in range(P.m):
        f0, f1, f2 = hv[i, 0], hv[i, 1], hv[i, 2]
        for k in range(e):
            f0 += D[i, 0, k] * y[k]
        for k in range(e):
            f1 += D[i, 1, k] * y[k]
        for k in range(e):
            f2 += D[i, 2, k] * y[k]
        ft = P.mu * math.sqrt(f1 * f1 + f2 * f2)
        norm += f0 * f0 + ft * ft
        if i < P.q:
            viol = max(viol, P.f_min - f0, ft - P.mu * f0)
    for k in range(P.nl):
        # a linear row's slack hl + DL y (N) must be >= 0
        acc = hl[k]
        for j in range(e):
            acc += DL[k, j] * y[j]
        viol = max(viol, -acc)
    norm = math.sqrt(norm)
    if viol > opt.violation_tol * max(1.0, norm):
        return UNDECIDED, math.nan, math.nan, it
    return code, norm, viol, it


@jit_inline
def solve_one(P, W, Q, opt, y):
    """`attempt`, and a second one with refinement if the first leaves the problem undecided.
    Returns (code, ||f|| N, worst violation N, iterations of both); fills y."""
    code, norm, viol, it = UNDECIDED, math.nan, math.nan, 0
    for second in range(2):
        if second and not (code == UNDECIDED and opt.retry_refine > opt.refine):
            break
        # Undecided problems are mostly stalls at a degenerate optimum, where the normal
        # equations lose accuracy: a second attempt with iterative refinement decides most.
        code, norm, viol, it_k = attempt(P, W, Q, opt, opt.retry_refine if second else opt.refine, y)
        it += it_k
    return code, norm, viol, it


@jit_call
def cone_rows(frames, mu, rows):
    """Kernel form of the circular cone from the contact frames (m, 3, 3) [n; t1; t2]:
    rows [n; t1/mu; t2/mu], so that the cone is rows @ f_i in SOC(3) and the linear row
    n.f - f_min >= 0 is its first row."""
    for i in range(frames.shape[0]):
        for q in range(3):
            rows[i, 0, q] = frames[i, 0, q]
            rows[i, 1, q] = frames[i, 1, q] / mu
            rows[i, 2, q] = frames[i, 2, q] / mu


@jit_inline
def rotate(R, start, s):
    """One-sided Jacobi (Hestenes) on the first s columns of R (c, >= s), in place: plane
    rotations of pairs of columns until every pair is orthogonal to ~1e-15 relative; the
    columns are then U Sigma, their norms the singular values, to high relative accuracy.
    The first `start` columns are already mutually orthogonal (a subset's rotated columns):
    the first sweep takes only the pairs with a later column. Sets hold 1 to 15 synergies,
    so this is a few sweeps of short loops, without LAPACK's copies, workspace query and
    allocations."""
    c = R.shape[0]
    tol = 1e-15 * c
    for _ in range(60):
        rotated = False
        for a in range(s - 1):
            for b in range(max(a + 1, start), s):
                alpha = 0.0
                beta = 0.0
                gamma = 0.0
                for k in range(c):
                    alpha += R[k, a] * R[k, a]
                    beta += R[k, b] * R[k, b]
                    gamma += R[k, a] * R[k, b]
                if abs(gamma) <= tol * math.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = math.copysign(1.0, zeta) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                cs = 1.0 / math.sqrt(1.0 + t * t)
                sn = cs * t
                for k in range(c):
                    ua, ub = R[k, a], R[k, b]
                    R[k, a] = cs * ua - sn * ub
                    R[k, b] = sn * ua + cs * ub
        start = 0
        if not rotated:
            break


@jit_inline
def kept_directions(R, s, threshold, U):
    """The rotated columns of R (the first s) whose norm exceeds `threshold`, normalised, into
    the leading columns of U (R itself allowed); returns their number."""
    c = R.shape[0]
    rank = 0
    for q in range(s):
        norm = 0.0
        for k in range(c):
            norm += R[k, q] * R[k, q]
        norm = math.sqrt(norm)
        if norm > threshold:
            for k in range(c):
                U[k, rank] = R[k, q] / norm
            rank += 1
    return rank


@jit_call
def set_bases(F_all, cols, n_cols, thresholds, parent, order, rotated, bases, e_s):
    """E_s of every set into bases (n_sets, c, >= s): an orthonormal basis of the range of
    F_s = F_all[:, cols[j, :s]] from its singular vectors whose singular value exceeds the set's
    threshold (the rule of `mechanics.internal_force_basis`), by one-sided Jacobi rotations
    (`rotate`, `kept_directions`); its rank into e_s; in `order` (parents first). A set whose
    parent (the set without its last column; -1: none)
    is known starts from the parent's rotated columns, already orthogonal, and the new
    column (`rotate`): the incremental sets {S1..Sk} cost a few sweeps over k - 1 pairs
    instead of Jacobi from scratch. rotated (n_sets, c, >= s): the rotated columns."""
    c = F_all.shape[0]
    for j in order:
        s, p, R = n_cols[j], parent[j], rotated[j]
        start = 0 if p < 0 else s - 1
        for q in range(start):
            for k in range(c):
                R[k, q] = rotated[p, k, q]
        for q in range(start, s):
            for k in range(c):
                R[k, q] = F_all[k, cols[j, q]]
        rotate(R, start, s)
        e_s[j] = kept_directions(R, s, thresholds[j], bases[j])


@jit_alloc
def solve_sets(
    F_all, fp, frames, cols, n_cols, thresholds, given, nesting, cone, cone_strict, f_min, strict, opt, opt_strict, out
):
    """Every synergy set of one grasp into `out` (`SetsResult`): E_s from the singular vectors
    of F_s = F_all[:, set] whose singular value is above the set's threshold (`set_bases`),
    or, if `given`, F_s itself (orthonormal columns), then the GFO, its forces f_p + E_s y (N)
    and, if `strict`, the strict internal-force test (f_p = 0, f_min = 1 N, cone_strict).
    cone, cone_strict: `ConeData` of the same kind; opt, opt_strict: `Settings` of the GFO and
    of the strict test (feasibility only). Sets with e_s = 0 get code NOT_SOLVED.
    nesting: `Nesting` of the sets: parent (n_sets,) the index of the set without the last
    column, -1 for none (`set_bases`), and within (n_sets, n_sets) bool: within[a, b] if
    set a is a subset of set b (a != b); then
    range(E_a) is in range(E_b), so b infeasible implies a infeasible and a strictly
    feasible implies b strictly feasible; of equal rank the two subspaces are equal, the
    problems the same (a takes b's verdict, ||f|| and forces). A set whose GFO is infeasible
    has no strictly internal force (one would make the GFO feasible, scaled up). Implied
    verdicts are not solved (`out.implied`, 0 iterations); all False: every set solved."""
    c = F_all.shape[0]
    m, p = c // 3, cone.lin.shape[1]
    rows = np.empty((m, 3, 3))
    cone_rows(frames, cone.mu, rows)
    W = workspace(m, m if p == 0 else 0, m * p, cols.shape[1])
    Q = polish_workspace(cols.shape[1])
    y = np.empty(cols.shape[1])
    bases = np.empty((cols.shape[0], c, cols.shape[1]))
    order = nesting.order  # subsets before their supersets
    if given:
        for j in order:
            out.e_s[j] = n_cols[j]
            for q in range(n_cols[j]):
                for k in range(c):
                    bases[j, k, q] = F_all[k, cols[j, q]]
    else:
        set_bases(F_all, cols, n_cols, thresholds, nesting.parent, order, np.empty_like(bases), bases, out.e_s)
    # The GFO of every set, supersets first, then (if `strict`) the strict test, subsets
    # first, in one loop with one call of `solve_one` (inlined, `ipm.compiled`).
    zero = np.zeros(c)
    for phase in range(2 if strict else 1):
        gfo = phase == 0
        if not gfo:
            cone_rows(frames, cone_strict.mu, rows)
        sequence = nesting.order[::-1] if gfo else nesting.order
        for j in sequence:
            rank = out.e_s[j]
            if rank == 0:
                if gfo:
                    out.code[j] = NOT_SOLVED
                continue
            if gfo:
                k = implying(nesting.within[j], out.code, INFEASIBLE, out.e_s, rank)
                if k >= 0:
                    out.implied[j] = True
                    out.code[j] = out.code[k]
                    if out.code[k] == OPTIMAL:  # the same subspace: the same problem, the same optimum
                        out.force_norm[j], out.max_violation[j] = out.force_norm[k], out.max_violation[k]
                        for q in range(c):  # a loop, not a slice copy: that compiles numba's shape-error text
                            out.forces[j, q] = out.forces[k, q]
                    continue
                # E_s is the first `rank` columns of bases[j]
                P = build(rows, cone.lin, bases[j], fp, rank, cone.mu, f_min, W)
            else:
                # Not strictly feasible where the GFO is infeasible, strictly feasible where a
                # subset is, the verdict of a subset of the same rank, else solved.
                if out.code[j] == INFEASIBLE:
                    out.strict_code[j] = INFEASIBLE
                    continue
                k = implying(nesting.within[:, j], out.strict_code, OPTIMAL, out.e_s, rank)
                if k >= 0:
                    out.strict_code[j] = out.strict_code[k]
                    continue
                P = build(rows, cone_strict.lin, bases[j], zero, rank, cone_strict.mu, 1.0, W)
            code, norm, viol, its = solve_one(P, W, Q, opt if gfo else opt_strict, y)
            if not gfo:
                out.strict_code[j] = code
                continue
            out.code[j], out.force_norm[j], out.max_violation[j], out.iterations[j] = code, norm, viol, its
            if code == OPTIMAL:
                U = bases[j]
                for k in range(c):
                    acc = fp[k]
                    for q in range(rank):
                        acc += U[k, q] * y[q]
                    out.forces[j, k] = acc


@jit_call
def implying(marked, codes, code, e_s, rank):
    """The set whose verdict a set of rank `rank` takes, among the sets `marked` (bool over
    the sets; its subsets or supersets): the first with `code`, else the first of the same
    rank (the same subspace) that the kernel decided; -1 if none."""
    for k in range(marked.shape[0]):
        if marked[k] and codes[k] == code:
            return k
    for k in range(marked.shape[0]):
        if marked[k] and e_s[k] == rank and (codes[k] == OPTIMAL or codes[k] == INFEASIBLE):
            return k
    return -1
