"""The kinematic closure's free steps, compiled (docs/closure.md; mm, rad).

Between two events (a link meeting the box or the hand), the closure only repeats one step:
the travel budget of each finger from the gaps at σ, the largest σ' that keeps every finger
within its budget, the gaps at σ'. :func:`march` repeats it in one compiled call until the
closure ends, stalls or a link crosses something in (σ, σ']; the events themselves (where
exactly the crossing is, which joints it holds) stay in ``KinematicClosure``. The same
floating-point operations in the same order as the step's Python form, so the closure's
results do not depend on which form ran.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.capsules import posture_gaps  # noqa: I001 (after the group's registration)
from synergrasp.simulation.shapes.compiled import jit, jit_inline  # registers the group first

__all__ = ["march", "MARCH_END", "MARCH_STALL", "MARCH_CROSS"]

#: How :func:`march` stopped: σ reached σ_closed; no finger can advance; a link crosses.
MARCH_END, MARCH_STALL, MARCH_CROSS = 0, 1, 2


@jit_inline
def _posture(
    sigma: float, held: NDArray, q_held: NDArray, mean: NDArray, direction: NDArray, lower: NDArray, upper: NDArray
) -> NDArray:
    """where(held, q_held, clip(mean + σ·direction, lower, upper)), rad."""
    q = np.empty(mean.shape[0])
    for j in range(mean.shape[0]):
        if held[j]:
            q[j] = q_held[j]
        else:
            q[j] = min(max(mean[j] + sigma * direction[j], lower[j]), upper[j])
    return q


@jit_inline
def _masked(d: NDArray, moving_links: NDArray, margin_mm: float) -> None:
    for i in range(d.shape[0]):
        if not moving_links[i] or d[i] > margin_mm:
            d[i] = np.inf


@jit_inline
def _smallest(d_obj: NDArray, d_self: NDArray) -> float:
    return min(d_obj.min(), d_self.min())


@jit_inline
def _advance(sigma: float, sigma_closed: float, budget: NDArray, knots: NDArray, travel: NDArray, n_knots: NDArray) -> float:
    """Largest σ' ≤ σ_closed such that no finger f travels more than budget[f] mm on [σ, σ']:
    knots[f, :n_knots[f]] and travel[f, :n_knots[f]] its
    piecewise linear travel bound for its moving joints (n_knots[f] = 0: nothing moves)."""
    best = sigma_closed
    for f in range(n_knots.shape[0]):
        n = n_knots[f]
        if n == 0:
            continue
        i = 0
        while i < n and knots[f, i] <= sigma:  # bisect_right
            i += 1
        i = min(max(i, 1), n - 1)
        level = travel[f, i - 1] + (sigma - knots[f, i - 1]) / (knots[f, i] - knots[f, i - 1]) * (travel[f, i] - travel[f, i - 1])
        level += budget[f]
        if level > travel[f, n - 1]:
            continue  # the budget outlasts the closure
        k = 0
        while k < n and travel[f, k] < level:  # bisect_left: travel[k-1] < level <= travel[k]
            k += 1
        t0, t1 = travel[f, k - 1], travel[f, k]
        candidate = knots[f, k - 1] + (level - t0) / (t1 - t0) * (knots[f, k] - knots[f, k - 1])
        if candidate < best:
            best = candidate
    return best


@jit_inline
def _budget(d_obj: NDArray, d_self: NDArray, finger_links: NDArray, step_mm: float, margin_mm: float) -> NDArray:
    """Travel budget (mm) per finger: max(step_mm, min(its free distance, margin_mm)); hand
    gaps count half."""
    out = np.empty(finger_links.shape[0])
    for f in range(finger_links.shape[0]):
        free = np.inf
        for link in range(finger_links.shape[1]):
            if finger_links[f, link]:
                free = min(free, min(d_obj[link], 0.5 * d_self[link]))
        out[f] = max(step_mm, min(free, margin_mm))
    return out


@jit_inline
def _gaps(
    sigma: float,
    held: NDArray,
    q_held: NDArray,
    path: tuple,
    scene: tuple,
    pair_rows: tuple,
    moving_links: NDArray,
    margin_mm: float,
) -> tuple:
    """(q, d_obj, d_self, partner) at σ: the posture and the gaps of the moving links within
    ``margin_mm`` (+inf for the others; ``KinematicClosure.gaps``)."""
    mean, direction, lower, upper = path
    (parent, offset, axis, joint, scale, cap_frame, ends, radius, cap_link, palm_gap, rotation, centre, code, params, bound) = (
        scene
    )
    first, second, pair_ends, palm_rotation, palm_centre, palm_half, n_links = pair_rows
    q = _posture(sigma, held, q_held, mean, direction, lower, upper)
    d_obj, d_self, partner = posture_gaps(
        q,
        parent,
        offset,
        axis,
        joint,
        scale,
        cap_frame,
        ends,
        radius,
        cap_link,
        palm_gap,
        rotation,
        centre,
        code,
        params,
        bound,
        first,
        second,
        pair_ends,
        palm_rotation,
        palm_centre,
        palm_half,
        n_links,
        moving_links,
        margin_mm,
    )
    _masked(d_obj, moving_links, margin_mm)
    _masked(d_self, moving_links, margin_mm)
    return q, d_obj, d_self, partner


@jit
def march(
    sigma: float,
    sigma_closed: float,
    now: tuple,
    known: bool,
    held: NDArray,
    q_held: NDArray,
    path: tuple,
    scene: tuple,
    pair_rows: tuple,
    moving_links: NDArray,
    finger_links: NDArray,
    knots: NDArray,
    travel: NDArray,
    n_knots: NDArray,
    step_mm: float,
    margin_mm: float,
    tolerance_mm: float,
    max_refine: int,
) -> tuple:
    """Free steps of the closure from σ until it ends (MARCH_END), stalls (MARCH_STALL) or a
    moving link crosses the box or the hand in (σ, σ'] (MARCH_CROSS), then the event there.

    ``now`` = (q, d_obj, d_self, partner): the gaps at σ when ``known``, else computed.
    ``path`` = (mean, direction, lower, upper) of the reference (rad); ``scene`` and
    ``pair_rows``: the arguments of ``capsules.posture_gaps`` (``HandScene.query_args``,
    ``pair_args``). Returns (status, σ, gaps): at MARCH_END and MARCH_STALL the σ reached and
    the gaps there; at MARCH_CROSS the σ of the event and its gaps (:func:`_event`).
    """
    if not known:
        now = _gaps(sigma, held, q_held, path, scene, pair_rows, moving_links, margin_mm)
    while sigma < sigma_closed:
        budget = _budget(now[1], now[2], finger_links, step_mm, margin_mm)
        sigma_next = _advance(sigma, sigma_closed, budget, knots, travel, n_knots)
        if sigma_next <= sigma:
            return MARCH_STALL, sigma, now
        after = _gaps(sigma_next, held, q_held, path, scene, pair_rows, moving_links, margin_mm)
        if _smallest(after[1], after[2]) < 0.0:
            lo, event = _event(
                sigma,
                now,
                sigma_next,
                after,
                held,
                q_held,
                path,
                scene,
                pair_rows,
                moving_links,
                margin_mm,
                tolerance_mm,
                max_refine,
            )
            return MARCH_CROSS, lo, event
        sigma, now = sigma_next, after
    return MARCH_END, sigma, now


@jit_inline
def _event(
    sigma: float,
    now: tuple,
    sigma_next: float,
    after: tuple,
    held: NDArray,
    q_held: NDArray,
    path: tuple,
    scene: tuple,
    pair_rows: tuple,
    moving_links: NDArray,
    margin_mm: float,
    tolerance_mm: float,
    max_refine: int,
) -> tuple:
    """A moving link crosses something in (σ, σ_next]: the last σ before it, where the
    smallest gap is in [0, tolerance_mm] (Illinois false position, bisection when it
    stalls), and the gaps there (``now``'s at σ when no step forward stays clear)."""
    lo, hi = sigma, sigma_next
    d_lo, d_hi = _smallest(now[1], now[2]), _smallest(after[1], after[2])
    side, event = 0, now
    for _ in range(max_refine):
        mid = 0.5 * (lo + hi)
        if np.isfinite(d_lo) and (hi - lo) > 1e-12:
            guess = hi - d_hi * (hi - lo) / (d_hi - d_lo)
            if lo < guess < hi:
                mid = guess
        at = _gaps(mid, held, q_held, path, scene, pair_rows, moving_links, margin_mm)
        smallest = _smallest(at[1], at[2])
        if smallest < 0.0:
            hi, d_hi = mid, smallest
            if side == -1:
                d_lo = 0.5 * d_lo
            side = -1
            continue
        lo, d_lo, event = mid, smallest, at
        if smallest <= tolerance_mm:
            break
        if side == +1:
            d_hi = 0.5 * d_hi
        side = +1
    return lo, event
