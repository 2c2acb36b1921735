"""The joint estimate's least squares (:mod:`.joint`, whose module doc gives the model): each
walk's correction knots, their priors and PDR chains, the iteratively reweighted solve with the
links, and each point's σ after it — narrowed by the links, widened by what they still
disagree on."""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from workstation.fingerprints.localize import Fingerprints

if TYPE_CHECKING:  # SciPy is imported where it is used
    from scipy.sparse import spmatrix

KNOT_S = 10.0  # seconds between a walk's correction knots
SIGMA_TO_AXIS = 1.5  # σ (radius holding ~68 %) = 1.5 × the per-axis spread of a 2-D Gaussian
SIGMA_CAP_M = 10.0  # a point with no σ (inf) or a larger one counts as this
SIGMA_FLOOR_M = 0.5  # … and one below as this: no walk is certain to the centimetre
CHAIN_M = 0.5  # σ of the bend between two knots, per axis …
CHAIN_DRIFT = 0.10  # … plus this per metre walked between them
LINK_DEPENDENCE = 2.0  # a walk's links count as this² times fewer for σ (module doc)
LINK_M = 4.0  # σ per axis of "stood at the same place" for two nearest fingerprints
HUBER_C = 1.0  # the robust kernel's knee, in LINK_M (Huber below, then Cauchy-like decay)
ITERATIONS = 8
BIAS_GAIN = 2.0  # a point's σ widens by this × the bias its nearby links still show …
BIAS_NOISE = 4.0  # … beyond this × LINK_M / √(links): what k links' median wanders by chance
BIAS_MIN_LINKS = 10  # … over at least this many links (fewer: nothing said)
PINNED = 1e-3  # a fixed map's prior, as a share of its σ: it does not move


def robust_weight(r: np.ndarray, scale: float) -> np.ndarray:
    """IRLS weight of a residual of length ``r``: 1 up to ``HUBER_C``·scale, then falling as
    (knee / r)² — a wrong link far off costs next to nothing, a link a few σ off still pulls
    (Cauchy-like; the estimate starts where the walks' own runs placed them, so the convex
    start of graduated non-convexity is that placement)."""
    knee = HUBER_C * scale
    return np.where(r <= knee, 1.0, (knee / np.maximum(r, 1e-12)) ** 2)


def knots_of(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A walk's knots (times) and per row its two knots' local indices and the weight of the
    second: the correction at row i is (1 − a_i) c[k_i] + a_i c[k_i + 1]."""
    lo, hi = float(t.min()), float(t.max())
    n = max(1, int(np.ceil((hi - lo) / KNOT_S)))
    knots = np.linspace(lo, hi, n + 1) if hi > lo else np.array([lo])
    if knots.size == 1:
        return knots, np.zeros(t.size, int), np.zeros(t.size)
    k = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, knots.size - 2)
    a = (t - knots[k]) / (knots[k + 1] - knots[k])
    return knots, k, np.clip(a, 0.0, 1.0)


@dataclass(frozen=True)
class Design:
    """The floor's knots (every walk's, numbered across walks) and the fixed part of the normal
    equations: ``C`` (rows × knots) gives each row's correction from the knots', ``H0`` holds
    the priors and the chains (module doc)."""

    C: spmatrix
    H0: spmatrix
    ka: np.ndarray  # each row's two knots and their weights
    kb: np.ndarray
    wa: np.ndarray
    own_sigma: np.ndarray  # each row's σ from its own run (inf: none)
    knot_start: np.ndarray  # each walk's first knot, and the count at the end
    row_start: np.ndarray  # each walk's first row, and the count at the end

    @property
    def n_k(self) -> int:
        return int(self.knot_start[-1])

    @classmethod
    def of(cls, names: list[str], fps: list[Fingerprints], fixed: Collection[str]) -> Design:
        import scipy.sparse as sp

        ka, kb, wa, wb, prior, chain, own = [], [], [], [], [], [], []
        first, knot_firsts = 0, []
        for name, m in zip(names, fps):
            knot_firsts.append(first)
            t = m.t if m.t is not None else np.zeros(len(m))
            knots, k, a = knots_of(t)
            ka.append(first + k)
            kb.append(first + np.minimum(k + 1, knots.size - 1))
            wa.append(1 - a)
            wb.append(a)
            sig = m.sigma if m.sigma is not None else np.full(len(m), np.inf)
            own.append(np.where(np.isfinite(sig), sig, np.inf))
            prior.append(_knot_prior(sig, k, a, knots.size) * (PINNED if name in fixed else 1.0))
            if knots.size > 1:
                chain.append((first + np.arange(knots.size - 1), _chain_sd(m, t, knots)))
            first += knots.size
        n = sum(len(m) for m in fps)
        C = sp.csr_matrix((np.concatenate(wa + wb), (np.tile(np.arange(n), 2),
                           np.concatenate(ka + kb))), shape=(n, first))  # fmt: skip
        H0 = sp.diags(1.0 / np.concatenate(prior) ** 2)
        if chain:
            ci = np.concatenate([c[0] for c in chain])
            cs = np.concatenate([c[1] for c in chain])
            D = sp.csr_matrix((np.concatenate([np.ones(ci.size), -np.ones(ci.size)]),
                               (np.tile(np.arange(ci.size), 2), np.concatenate([ci + 1, ci]))),
                              shape=(ci.size, first))  # fmt: skip
            H0 = H0 + D.T @ sp.diags(1.0 / cs**2) @ D
        rows = np.concatenate([[0], np.cumsum([len(m) for m in fps])])
        return cls(C, H0, np.concatenate(ka), np.concatenate(kb), np.concatenate(wa),
                   np.concatenate(own), np.array(knot_firsts + [first]), rows)  # fmt: skip


def _knot_prior(sig: np.ndarray, k: np.ndarray, a: np.ndarray, n_knots: int) -> np.ndarray:
    """Each knot's prior: the walk's σ near it as a per-axis spread (module doc)."""
    sig = np.clip(np.where(np.isfinite(sig), sig, SIGMA_CAP_M), SIGMA_FLOOR_M, SIGMA_CAP_M)
    near = np.where(a < 0.5, k, np.minimum(k + 1, n_knots - 1))
    s = np.array([np.median(sig[near == j]) if (near == j).any() else np.median(sig)
                  for j in range(n_knots)])  # fmt: skip
    return s / SIGMA_TO_AXIS


def _chain_sd(m: Fingerprints, t: np.ndarray, knots: np.ndarray) -> np.ndarray:
    """σ of the bend between consecutive knots: the PDR chain drifts with the distance walked."""
    order = np.argsort(t, kind="stable")
    step = np.hypot(np.diff(m.x[order]), np.diff(m.y[order]))
    walked = np.concatenate([[0.0], np.cumsum(step)])
    return CHAIN_M + CHAIN_DRIFT * np.diff(np.interp(knots, t[order], walked))


def solve(
    H0: spmatrix, L: spmatrix, bx: np.ndarray, by: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Iteratively reweighted least squares: the corrections of every knot (x, y) and the
    links' last weights."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import splu

    cx, cy = np.zeros(H0.shape[0]), np.zeros(H0.shape[0])
    w = np.ones(L.shape[0])
    for _ in range(ITERATIONS):
        if L.shape[0]:
            rx, ry = L @ cx - bx, L @ cy - by
            w = robust_weight(np.hypot(rx, ry), LINK_M)
        H = (H0 + L.T @ sp.diags(w / LINK_M**2) @ L).tocsc()
        lu = splu(H)
        cx, cy = lu.solve(L.T @ (w * bx) / LINK_M**2), lu.solve(L.T @ (w * by) / LINK_M**2)
    return cx, cy, w


def narrowed(d: Design, L: spmatrix, w: np.ndarray) -> np.ndarray:
    """How much the other walks' evidence narrows each row's correction: the marginal with the
    links over the marginal without, diag(C H⁻¹ Cᵀ) both (one H for both axes), the links'
    information divided by LINK_DEPENDENCE² (a walk's links are not independent: neighbouring
    scans match alike); each walk's knots given the others' (a small dense block)."""
    import scipy.sparse as sp

    Hp = d.H0.tocsr()
    Hm = (Hp + L.T @ sp.diags(w / (LINK_M * LINK_DEPENDENCE) ** 2) @ L).tocsr()
    n = int(d.row_start[-1])
    var_post, var_prior = np.empty(n), np.empty(n)
    for i in range(d.knot_start.size - 1):
        k0, k1 = d.knot_start[i], d.knot_start[i + 1]
        r0, r1 = d.row_start[i], d.row_start[i + 1]
        Ci = d.C[r0:r1, k0:k1].toarray()
        for H_, out_ in ((Hm, var_post), (Hp, var_prior)):
            cov = np.linalg.inv(H_[k0:k1, k0:k1].toarray())
            out_[r0:r1] = np.einsum("ij,jk,ik->i", Ci, cov, Ci)
    return np.sqrt(np.clip(var_post / np.maximum(var_prior, 1e-12), 0.0, 1.0))


def bias(knot: np.ndarray, rx: np.ndarray, ry: np.ndarray, knot_start: np.ndarray,
          n_k: int) -> np.ndarray:  # fmt: skip
    """Per knot, how far the links of its walk's rows near it (that knot and its neighbours)
    still disagree after the estimate, beyond chance: the length of their median residual less
    ``BIAS_NOISE`` · ``LINK_M`` / √k, floored at 0 (fewer than ``BIAS_MIN_LINKS``: 0). What the estimate
    could not move away — a walk its own σ held where the others' WiFi says it is not — is
    uncertainty its points carry (σ widens; the module doc)."""
    import pandas as pd

    out = np.zeros(n_k)
    if not knot.size:
        return out
    walk_of = np.repeat(np.arange(knot_start.size - 1), np.diff(knot_start))
    # each link counts for its knot and the two beside it, within its walk
    to = np.concatenate([knot - 1, knot, knot + 1])
    src = np.tile(np.arange(knot.size), 3)
    ok = (to >= 0) & (to < n_k)
    ok[ok] &= walk_of[to[ok]] == walk_of[knot[src[ok]]]
    g = pd.DataFrame({"k": to[ok], "x": rx[src[ok]], "y": ry[src[ok]]}).groupby("k")
    med, n = g.median(), g.size()
    d = np.hypot(med["x"].to_numpy(), med["y"].to_numpy())
    excess = np.maximum(0.0, d - BIAS_NOISE * LINK_M / np.sqrt(n.to_numpy()))
    out[med.index.to_numpy()] = np.where(n.to_numpy() >= BIAS_MIN_LINKS, excess, 0.0)
    return out
