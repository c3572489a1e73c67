# ruff: noqa: E741  (l / r are the left and right images, as in algorithms.md)
"""NumPy reference of the MCGM channel (rust/core/src/matching/mcgm), written for clarity.

Each stage is a plain function so a test can feed it the Rust output of the previous stage and
compare one stage at a time:

* :func:`log_filter` -- float64 separable zero-mean scale-normalised LoG (reflect-101 borders);
* :func:`zero_crossings` -- marks, sub-pixel x, strength and orientation, in float32 like Rust;
* :func:`track` -- hysteresis tracking (seed order, forward half-plane, tangent sign);
* :func:`ght_vote` / :func:`candidates` -- R-table voting and the candidate gates;
* :func:`mcgm_match` -- the whole channel (graph, Hopfield solver of ``hopfield_ref``, prior
  spreading, decomposition, combination, filters).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from tests.reference import hopfield_ref

ZC_H, ZC_V = 1, 2
#: Crossings weaker than this are phantom (float rounding in flat areas; zerocross.rs).
MIN_STRENGTH = np.float32(1e-5)
#: ``2 sqrt 2`` as Rust computes it in f32.
CHANNEL_WIDTH_SIGMAS = np.float32(2.0) * np.float32(math.sqrt(2.0))
NEIGHBOURS = [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)]
SPREAD_ORDER = [(0, -1), (-1, 0), (1, 0), (0, 1), (-1, -1), (1, -1), (-1, 1), (1, 1)]

DEFAULTS: dict[str, Any] = {
    "sigmas": [4.0, 2.0, 1.0],
    "half_res_sigma": 4.0,
    "high_quantile": 0.5,
    "low_ratio": 0.4,
    "max_turn_deg": 60.0,
    "min_len": 8,
    "min_len_sigmas": 4.0,
    "seg_theta_tol_deg": 30.0,
    "dy_band": 1,
    "n_theta_bins": 36,
    "vote_bin_tol": 2,
    "ght_min_score": 0.4,
    "k_cand": 6,
    "knn": 6,
    "r_graph": 60.0,
    "A": 1.0,
    "B": 1.5,
    "D": 1.0,
    "theta": 0.3,
    "dg_0": 0.5,
    "dg_slope": 10.0,
    "max_sweeps": 100,
    "seed": 0,
    "horiz_skip_deg": 20.0,
    "prior_radius_sigmas": 4.0,
    "prior_width_sigmas": float(CHANNEL_WIDTH_SIGMAS),
    "fill_radius": 1,
    "sides": True,
    "sides_mad": 0.06,
    "sides_width": 6,
    "sides_height": 7,
    "sides_gap": 1,
    "sides_best": True,
    "sides_best_margin": 0.0,
    "sides_mean_free": True,
    "disc": True,
    "disc_dx": 6,
    "disc_dy": 2,
    "disc_tol": 1.0,
    "zncc_check": True,
    "zncc_tol": 0.5,
}


def rround(v: float) -> int:
    """Rust's ``f32::round``: halfway cases away from zero (``np.rint`` rounds them to even)."""
    v = float(v)
    return math.floor(v + 0.5) if v >= 0 else -math.floor(-v + 0.5)


# --- B.3 LoG ---


def log_kernels(sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """``(g, a)`` float64 taps ``-r..r``, ``r = ceil(4 sigma)``; ``a`` zero-mean."""
    r = max(1, math.ceil(4.0 * sigma))
    t = np.arange(-r, r + 1, dtype=np.float64)
    s2 = sigma * sigma
    g = np.exp(-(t * t) / (2.0 * s2))
    a = (t * t / s2 - 1.0) * g / (2.0 * math.pi * s2)
    a = a - g * a.sum() / g.sum()
    return g, a


def _reflect(i: np.ndarray, n: int) -> np.ndarray:
    if n == 1:
        return np.zeros_like(i)
    i = i.copy()
    while True:
        lo, hi = i < 0, i >= n
        if not (lo.any() or hi.any()):
            return i
        i[lo] = -i[lo]
        i[hi] = 2 * (n - 1) - i[hi]


def _conv_rows(img: np.ndarray, k: np.ndarray) -> np.ndarray:
    h, w = img.shape
    r = len(k) // 2
    idx = _reflect(np.arange(-r, w + r), w)
    p = img[:, idx]
    out = np.zeros((h, w))
    for j in range(len(k)):
        out += k[j] * p[:, j : j + w]
    return out


def log_filter(img: np.ndarray, sigma: float) -> np.ndarray:
    """``I * (a(x) g(y) + g(x) a(y))`` in float64."""
    g, a = log_kernels(sigma)
    x = img.astype(np.float64)
    hg, ha = _conv_rows(x, g), _conv_rows(x, a)
    return _conv_rows(ha.T, g).T + _conv_rows(hg.T, a).T


def decimate2(img: np.ndarray) -> np.ndarray:
    """2x2 means (float32, Rust's summation order)."""
    h, w = img.shape
    h2, w2 = max(1, h // 2), max(1, w // 2)
    ys0 = np.minimum(2 * np.arange(h2), h - 1)
    ys1 = np.minimum(2 * np.arange(h2) + 1, h - 1)
    xs0 = np.minimum(2 * np.arange(w2), w - 1)
    xs1 = np.minimum(2 * np.arange(w2) + 1, w - 1)
    f = img.astype(np.float32)
    s = f[np.ix_(ys0, xs0)] + f[np.ix_(ys0, xs1)] + f[np.ix_(ys1, xs0)] + f[np.ix_(ys1, xs1)]
    return (np.float32(0.25) * s).astype(np.float32)


# --- B.4.2-3 zero crossings ---


def zero_crossings(lg: np.ndarray) -> dict[str, np.ndarray]:
    """Marks, sub-pixel x, strength and normal direction of a float32 LoG response."""
    L = lg.astype(np.float32)
    h, w = L.shape
    mark = np.zeros((h, w), np.uint8)
    xsub = np.full((h, w), np.nan, np.float32)

    def inside(x: int, y: int) -> bool:
        return 1 <= x < w - 1 and 1 <= y < h - 1

    for y in range(1, h - 1):
        row = L[y]
        for x in range(w - 1):
            a, b = row[x], row[x + 1]
            if a * b < 0:
                px = x if abs(a) <= abs(b) else x + 1
                pos = np.float32(x) + a / (a - b)
            elif a == 0 and x >= 1 and row[x - 1] * b < 0:
                px, pos = x, np.float32(x)
            else:
                continue
            if not inside(px, y):
                continue
            if not (mark[y, px] & ZC_H) or abs(pos - np.float32(px)) < abs(
                xsub[y, px] - np.float32(px)
            ):
                xsub[y, px] = pos
            mark[y, px] |= ZC_H
    for y in range(h - 1):
        for x in range(1, w - 1):
            a, b = L[y, x], L[y + 1, x]
            if a * b < 0:
                py = y if abs(a) <= abs(b) else y + 1
            elif a == 0 and y >= 1 and L[y - 1, x] * b < 0:
                py = y
            else:
                continue
            if inside(x, py):
                mark[py, x] |= ZC_V
    strength = np.zeros((h, w), np.float32)
    theta = np.zeros((h, w), np.float32)
    half = np.float32(0.5)
    tau = np.float32(2 * math.pi)
    for y, x in zip(*np.nonzero(mark), strict=True):
        gx = half * (L[y, x + 1] - L[y, x - 1])
        gy = half * (L[y + 1, x] - L[y - 1, x])
        st = np.sqrt(gx * gx + gy * gy)
        if st < MIN_STRENGTH:
            mark[y, x] = 0
            xsub[y, x] = np.nan
            continue
        strength[y, x] = st
        t = np.arctan2(gy, gx)
        theta[y, x] = (t + tau) % tau if t < 0 else t
        if not mark[y, x] & ZC_H:
            lm, lc, lp = L[y, x - 1], L[y, x], L[y, x + 1]
            if lm * lc < 0:
                xsub[y, x] = np.float32(x) - np.float32(1) + lm / (lm - lc)
            elif lc * lp < 0:
                xsub[y, x] = np.float32(x) + lc / (lc - lp)
            elif gx != 0 and abs(lc / gx) <= 1.0:
                xsub[y, x] = np.float32(x) - lc / gx
            else:
                xsub[y, x] = np.float32(x)
    return {"mark": mark, "xsub": xsub, "strength": strength, "theta": theta}


# --- B.4.4-6 tracking, segments, R-tables ---


def _wrap(d: float) -> float:
    if d > math.pi:
        d -= 2 * math.pi
    elif d <= -math.pi:
        d += 2 * math.pi
    return d


def track(zc: dict[str, np.ndarray], p: dict[str, Any], min_len: int) -> dict[str, Any]:
    """Hysteresis tracking; segments as lists of pixel indices ``y * w + x`` in curve order."""
    mark, s, th = zc["mark"], zc["strength"], zc["theta"]
    h, w = mark.shape
    sf, tf = s.ravel(), th.ravel()
    marked = np.flatnonzero(mark.ravel())
    if len(marked) == 0:
        return {"segments": [], "labels": np.full((h, w), -1, np.int32), "t_high": 0.0}
    vals = np.sort(sf[marked])
    k = min(math.floor(p["high_quantile"] * (len(vals) - 1)), len(vals) - 1)
    t_high = vals[k]
    t_low = np.float32(p["low_ratio"]) * t_high
    cand = (mark.ravel() != 0) & (sf >= t_low) & (sf > 0)
    seeds = [int(i) for i in np.flatnonzero(cand & (sf >= t_high))]
    seeds.sort(key=lambda i: (-float(sf[i]), i))
    max_turn = math.radians(p["max_turn_deg"])
    visited = np.zeros(h * w, bool)

    def tan(i: int) -> tuple[float, float]:
        t = float(tf[i])
        return -math.sin(t), math.cos(t)

    def grow(start: int, sign: float) -> list[int]:
        out: list[int] = []
        cur = start
        tx, ty = tan(start)
        d = (sign * tx, sign * ty)
        while True:
            cx, cy = cur % w, cur // w
            best = None
            for dx, dy in NEIGHBOURS:
                nx, ny = cx + dx, cy + dy
                if not (0 <= nx < w and 0 <= ny < h):
                    continue
                q = ny * w + nx
                if not cand[q] or visited[q]:
                    continue
                if abs(_wrap(float(tf[q]) - float(tf[cur]))) >= max_turn:
                    continue
                dot = (dx * d[0] + dy * d[1]) / math.sqrt(dx * dx + dy * dy)
                if dot <= 0:
                    continue
                if best is None or dot > best[0] or (dot == best[0] and sf[q] > best[1]):
                    best = (dot, sf[q], q, dx, dy)
            if best is None:
                return out
            _, _, q, dx, dy = best
            visited[q] = True
            out.append(q)
            tx, ty = tan(q)
            sg = 1.0 if tx * dx + ty * dy >= 0 else -1.0
            d = (sg * tx, sg * ty)
            cur = q

    segments: list[list[int]] = []
    labels = np.full(h * w, -1, np.int32)
    for sd in seeds:
        if visited[sd]:
            continue
        visited[sd] = True
        fwd = grow(sd, 1.0)
        bwd = grow(sd, -1.0)
        if 1 + len(fwd) + len(bwd) < min_len:
            continue
        pix = [*bwd[::-1], sd, *fwd]
        labels[pix] = len(segments)
        segments.append(pix)
    return {"segments": segments, "labels": labels.reshape(h, w), "t_high": float(t_high)}


def segment_info(pix: list[int], theta: np.ndarray, w: int) -> dict[str, Any]:
    """Centroid (float32 of the float64 mean), extents, circular mean orientation."""
    x = np.array([i % w for i in pix], np.int64)
    y = np.array([i // w for i in pix], np.int64)
    t = theta.ravel()[pix].astype(np.float64)
    m = math.atan2(float(np.sin(t).sum()), float(np.cos(t).sum()))
    m = m + 2 * math.pi if m < 0 else m
    return {
        "pixels": pix,
        "x": x,
        "y": y,
        "centroid": (np.float32(x.mean()), np.float32(y.mean())),
        "x_min": int(x.min()),
        "x_max": int(x.max()),
        "y_min": int(y.min()),
        "y_max": int(y.max()),
        "mean_theta": np.float32(m) % np.float32(2 * math.pi),
    }


def theta_bin(theta: float, k: int) -> int:
    return math.floor(float(theta) * k / (2 * math.pi)) % k


def rtable(seg: dict[str, Any], theta: np.ndarray, k: int) -> list[list[tuple[int, int]]]:
    """Per bin the pixels ``p`` of the segment (the vectors are ``c - p``)."""
    bins: list[list[tuple[int, int]]] = [[] for _ in range(k)]
    t = theta.ravel()
    for i, x, y in zip(seg["pixels"], seg["x"], seg["y"], strict=True):
        bins[theta_bin(t[i], k)].append((int(x), int(y)))
    return bins


# --- B.4.7-8 GHT and candidates ---


def ght_vote(
    rt: list[list[tuple[int, int]]],
    len_a: int,
    seg_b: dict[str, Any],
    theta_r: np.ndarray,
    lo: int,
    hi: int,
    dy: int,
    k: int,
    tol: int,
) -> tuple[float, float, float, int] | None:
    """``(score, tx, ty, peak)``: votes ``t = p - q`` over ``[lo, hi] x [-dy, dy]``."""
    if hi < lo or len_a == 0:
        return None
    nx = hi - lo + 1
    acc = np.zeros((2 * dy + 1, nx), np.int64)
    t = theta_r.ravel()
    for i, qx, qy in zip(seg_b["pixels"], seg_b["x"], seg_b["y"], strict=True):
        b = theta_bin(t[i], k)
        for db in range(-tol, tol + 1):
            for px, py in rt[(b + db) % k]:
                tx, ty = px - int(qx), py - int(qy)
                if lo <= tx <= hi and abs(ty) <= dy:
                    acc[ty + dy, tx - lo] += 1
    best = int(acc.max())
    if best == 0:
        return None
    cy, cx = np.unravel_index(int(np.argmax(acc)), acc.shape)
    sw = sx = sy = 0.0
    for yy in range(max(cy - 1, 0), min(cy + 1, 2 * dy) + 1):
        for xx in range(max(cx - 1, 0), min(cx + 1, nx - 1) + 1):
            v = float(acc[yy, xx])
            sw += v
            sx += v * (xx + lo)
            sy += v * (yy - dy)
    score = np.float32(best) / np.float32(max(len_a, len(seg_b["pixels"])))
    return float(score), float(np.float32(sx / sw)), float(np.float32(sy / sw)), best


def candidates(
    left: list[dict[str, Any]],
    rts: list[list[list[tuple[int, int]]]],
    right: list[dict[str, Any]],
    theta_r: np.ndarray,
    windows: list[tuple[int, int] | None],
    p: dict[str, Any],
) -> list[dict[str, Any]]:
    """Gated, GHT-scored candidates, best ``k_cand`` per left segment, grouped by left id."""
    tol = math.radians(p["seg_theta_tol_deg"])
    band = p["dy_band"]
    out: list[dict[str, Any]] = []
    for ia, a in enumerate(left):
        win = windows[ia]
        if win is None:
            continue
        lo, hi = win
        mine = []
        for ib, b in enumerate(right):
            if b["y_max"] < a["y_min"] - band or b["y_min"] > a["y_max"] + band:
                continue
            if abs(_wrap(float(a["mean_theta"]) - float(b["mean_theta"]))) >= tol:
                continue
            ov = min(a["y_max"] + band, b["y_max"]) - max(a["y_min"] - band, b["y_min"]) + 1
            ext = min(a["y_max"] - a["y_min"] + 1, b["y_max"] - b["y_min"] + 1)
            if ov < 0.5 * ext:
                continue
            slack = np.float32(0.5 * max(a["x_max"] - a["x_min"] + 1, b["x_max"] - b["x_min"] + 1))
            dc = a["centroid"][0] - b["centroid"][0]
            if dc < np.float32(lo) - slack or dc > np.float32(hi) + slack:
                continue
            g = ght_vote(
                rts[ia],
                len(a["pixels"]),
                b,
                theta_r,
                lo,
                hi,
                band,
                p["n_theta_bins"],
                p["vote_bin_tol"],
            )
            if g is not None and g[0] >= p["ght_min_score"]:
                mine.append({"left": ia, "right": ib, "score": g[0], "tx": g[1], "ty": g[2]})
        mine.sort(key=lambda c: (-c["score"], c["right"]))
        out.extend(mine[: p["k_cand"]])
    return out


# --- B.4.9-10 graph and solver ---


def knn_graph(segs: list[dict[str, Any]], k: int, r_max: float) -> list[list[int]]:
    n = len(segs)
    c = np.array([s["centroid"] for s in segs], np.float32).reshape(n, 2)
    adj: list[set[int]] = [set() for _ in range(n)]
    for i in range(n):
        d = np.sqrt(((c - c[i]) ** 2).sum(axis=1)).astype(np.float32)
        order = sorted((float(d[j]), j) for j in range(n) if j != i and d[j] <= np.float32(r_max))
        for _, j in order[:k]:
            adj[i].add(j)
            adj[j].add(i)
    return [sorted(a) for a in adj]


def association_rows(
    cands: list[dict[str, Any]],
    left: list[dict[str, Any]],
    adj: list[list[int]],
    p: dict[str, Any],
) -> list[list[tuple[int, float]]]:
    by_left: dict[int, list[int]] = {}
    by_right: dict[int, list[int]] = {}
    for i, c in enumerate(cands):
        by_left.setdefault(c["left"], []).append(i)
        by_right.setdefault(c["right"], []).append(i)
    f32 = np.float32
    rows = []
    for ia, ca in enumerate(cands):
        row: dict[int, float] = {}
        for ib in by_left[ca["left"]] + by_right[ca["right"]]:
            if ib != ia:
                row.setdefault(ib, float(-f32(p["B"])))
        sa = left[ca["left"]]
        deg_a = f32(len(adj[ca["left"]]))
        for nb in adj[ca["left"]]:
            sb = left[nb]
            dx = sa["centroid"][0] - sb["centroid"][0]
            dy = sa["centroid"][1] - sb["centroid"][1]
            dist = max(np.sqrt(f32(dx * dx + dy * dy)), f32(1.0))
            norm = f32(p["A"]) / np.sqrt(deg_a * f32(len(adj[nb])))
            for ib in by_left.get(nb, []):
                cb = cands[ib]
                if cb["right"] == ca["right"]:
                    continue
                ex, ey = f32(ca["tx"]) - f32(cb["tx"]), f32(ca["ty"]) - f32(cb["ty"])
                g = np.sqrt(ex * ex + ey * ey) / dist
                cc = f32(2.0) / (f32(1.0) + np.exp(f32(p["dg_slope"]) * (g - f32(p["dg_0"]))))
                row.setdefault(ib, float(norm * (cc - f32(1.0))))
        rows.append(sorted(row.items()))
    return rows


def solve(
    cands: list[dict[str, Any]], rows: list[list[tuple[int, float]]], p: dict[str, Any]
) -> list[int]:
    m = len(cands)
    inp = np.array(
        [float(np.float32(p["D"]) * np.float32(c["score"]) - np.float32(p["theta"])) for c in cands]
    )
    init = np.array(
        [1 if i == 0 or cands[i - 1]["left"] != cands[i]["left"] else 0 for i in range(m)]
    )
    state, _ = hopfield_ref.run_dynamics(rows, inp, init, p["seed"], p["max_sweeps"])
    net = inp.copy()
    for a in range(m):
        if state[a]:
            for b, t in rows[a]:
                net[b] += t
    best_left: dict[int, int] = {}
    for a in range(m):
        if state[a]:
            lft = cands[a]["left"]
            b = best_left.get(lft)
            if b is None or net[a] > net[b]:
                best_left[lft] = a
    best_right: dict[int, int] = {}
    for a in sorted(best_left.values()):
        rgt = cands[a]["right"]
        b = best_right.get(rgt)
        if b is None or net[a] > net[b]:
            best_right[rgt] = a
    return sorted(best_right.values())


# --- B.4.11-12 prior, decomposition, filters ---


def spread_prior(m: np.ndarray, radius: int) -> np.ndarray:
    """``radius`` synchronous 8-neighbour dilations of the valid values (first in order wins)."""
    cur = m.copy()
    h, w = cur.shape
    for _ in range(radius):
        valid = np.isfinite(cur)
        new = cur.copy()
        todo = ~valid
        for dx, dy in SPREAD_ORDER:
            sh = np.full((h, w), np.nan, np.float32)
            ys = slice(max(0, -dy), h - max(0, dy))
            yd = slice(max(0, dy), h - max(0, -dy))
            xs = slice(max(0, -dx), w - max(0, dx))
            xd = slice(max(0, dx), w - max(0, -dx))
            # sh[y, x] = cur[y + dy, x + dx]
            sh[ys, xs] = cur[yd, xd]
            take = todo & np.isfinite(sh)
            new[take] = sh[take]
            todo &= ~take
        if np.array_equal(np.isfinite(new), valid):
            break
        cur = new
    return cur


def _sample(img: np.ndarray, x: float, y: int) -> np.float32:
    w = img.shape[1]
    x = np.float32(x)
    x0 = min(math.floor(x), w - 1)
    x1 = min(x0 + 1, w - 1)
    f = x - np.float32(x0)
    return img[y, x0] + f * (img[y, x1] - img[y, x0])


def _half_mads(
    l: np.ndarray,
    r: np.ndarray,
    xi: int,
    yl: int,
    yr: int,
    ds: np.ndarray,
    side: int,
    geom: tuple[int, int, int],
    mean_free: bool,
) -> np.ndarray:
    """Half-window MADs for every disparity of ``ds`` (float32, Rust's sequential sums)."""
    inner, outer, hh = geom
    w = l.shape[1]
    dys = np.repeat(np.arange(-hh, hh + 1), outer - inner + 1)
    xs = np.tile(xi + side * np.arange(inner, outer + 1), 2 * hh + 1)
    lv = l[yl + dys, xs].astype(np.float32)  # (n,)
    pos = xs.astype(np.float32)[None, :] - ds.astype(np.float32)[:, None]  # (K, n)
    x0 = np.minimum(np.floor(pos).astype(np.int64), w - 1)
    x1 = np.minimum(x0 + 1, w - 1)
    f = (pos - x0.astype(np.float32)).astype(np.float32)
    ry = np.broadcast_to(yr + dys, pos.shape)
    a, b = r[ry, x0], r[ry, x1]
    rv = (a + f * (b - a)).astype(np.float32)
    n = np.float32(len(xs))
    diff = (lv[None, :] - rv).astype(np.float32)
    off = np.zeros(len(ds), np.float32)
    if mean_free:
        off = np.cumsum(diff, axis=1, dtype=np.float32)[:, -1] / n
    sad = np.cumsum(np.abs(diff - off[:, None]), axis=1, dtype=np.float32)[:, -1]
    return (sad / n).astype(np.float32)


def _other_better(
    l: np.ndarray,
    r: np.ndarray,
    xi: int,
    yl: int,
    yr: int,
    d: np.float32,
    side: int,
    geom: tuple[int, int, int],
    p: dict[str, Any],
    ks: tuple[int, int],
    here: np.float32,
) -> bool:
    """A half-window fits better at ``d + k`` (integer ``|k| > 1``, same interpolation weights)."""
    inner, outer, hh = geom
    w = r.shape[1]
    cols = xi + side * np.arange(inner, outer + 1)
    pos = cols.astype(np.float32) - d
    b = np.floor(pos).astype(np.int64)
    fr = (pos - b.astype(np.float32)).astype(np.float32)
    k_hi = min(ks[1], int(b.min()))
    k_lo = max(ks[0], int(b.max()) + 2 - w)
    kk = np.array([k for k in range(k_hi, k_lo - 1, -1) if abs(k) > 1], np.int64)
    if len(kk) == 0:
        return False
    dys = np.repeat(np.arange(-hh, hh + 1), len(cols))
    cc = np.tile(np.arange(len(cols)), 2 * hh + 1)
    lv = l[yl + dys, cols[cc]].astype(np.float32)[:, None]
    idx = b[cc][:, None] - kk[None, :]
    ry = (yr + dys)[:, None]
    a = r[ry, idx]
    v = a + fr[cc][:, None] * (r[ry, idx + 1] - a)
    diff = (lv - v).astype(np.float32)  # (n, K), raster order of the window
    n = np.float32(diff.shape[0])
    off = np.zeros(len(kk), np.float32)
    if p["sides_mean_free"]:
        off = np.cumsum(diff, axis=0, dtype=np.float32)[-1] / n
    sad = np.cumsum(np.abs(diff - off[None, :]), axis=0, dtype=np.float32)[-1]
    return bool(np.any(sad / n + np.float32(p["sides_best_margin"]) < here))


def sides_ok(
    l: np.ndarray, r: np.ndarray, m: np.ndarray, p: dict[str, Any], rng: tuple[int, int]
) -> bool:
    h, w = l.shape
    xl, yl, xr, yr = (np.float32(v) for v in m[:4])
    xi = rround(xl)
    yl_i, yr_i = rround(yl), rround(yr)
    d = np.float32(xl - xr)
    hh = p["sides_height"] // 2
    if yl_i - hh < 0 or yr_i - hh < 0 or yl_i + hh >= h or yr_i + hh >= h:
        return False
    inner, outer = p["sides_gap"] + 1, p["sides_gap"] + p["sides_width"]
    if xi - outer < 0 or xi + outer >= w:
        return False

    def fits(dd: np.ndarray) -> np.ndarray:
        return (np.float32(xi - outer) - dd >= 0) & (
            np.float32(xi + outer) - dd <= np.float32(w - 1)
        )

    if not fits(np.array([d]))[0]:
        return False
    geom = (inner, outer, hh)
    for side in (-1, 1):
        here = _half_mads(
            l, r, xi, yl_i, yr_i, np.array([d], np.float32), side, geom, p["sides_mean_free"]
        )[0]
        if here > np.float32(p["sides_mad"]):
            return False
        if p["sides_best"]:
            k0 = math.ceil(np.float32(rng[0]) - d)
            k1 = math.floor(np.float32(rng[1]) - d)
            if _other_better(l, r, xi, yl_i, yr_i, d, side, geom, p, (k0, k1), here):
                return False
    return True


def edge_filters(
    l: np.ndarray, r: np.ndarray, matches: np.ndarray, p: dict[str, Any], rng: tuple[int, int]
) -> np.ndarray:
    """Kept flags of ``(N, 4)`` matches: both-sides check, then the discontinuity filter."""
    h, w = l.shape
    n = len(matches)
    keep = np.array(
        [
            bool(np.all(np.isfinite(mm))) and (not p["sides"] or sides_ok(l, r, mm, p, rng))
            for mm in matches
        ],
        dtype=bool,
    ).reshape(n)
    if p["disc"] and n:
        xi = np.array([rround(v) for v in matches[:, 0]], np.int64)
        yi = np.array([rround(v) for v in matches[:, 1]], np.int64)
        d = (matches[:, 0] - matches[:, 2]).astype(np.float32)
        ins = (xi >= 0) & (yi >= 0) & (xi < w) & (yi < h)
        drop = np.zeros(n, bool)
        live = np.flatnonzero(keep & ins)
        for i in np.flatnonzero(keep):
            if not ins[i]:
                drop[i] = True
                continue
            near = live[
                (np.abs(xi[live] - xi[i]) <= p["disc_dx"])
                & (np.abs(yi[live] - yi[i]) <= p["disc_dy"])
                & (live != i)
            ]
            if np.any(np.abs(d[near] - d[i]) > np.float32(p["disc_tol"])):
                drop[i] = True
        keep &= ~drop
    if p["zncc_check"]:
        for i in np.flatnonzero(keep):
            keep[i] = area_ok(l, r, matches[i], p["zncc_tol"])
    return keep


def _zncc_window(img: np.ndarray, x: int, y: int) -> np.ndarray | None:
    """Mean-free float64 7x7 window at ``(x, y)``; None off the image or flat (std <= 1e-3)."""
    h, w = img.shape
    if x < 3 or y < 3 or x + 3 >= w or y + 3 >= h:
        return None
    v = img[y - 3 : y + 4, x - 3 : x + 4].astype(np.float64).ravel()
    v = v - v.mean()
    return v if math.sqrt(float(v @ v) / 49.0) > 1e-3 else None


def area_ok(l: np.ndarray, r: np.ndarray, m: np.ndarray, tol: float) -> bool:
    """Area check: 7x7 ZNCC at ``round(d) + k``, ``|k| <= 2``; the best (first of ties) is an
    interior peak whose parabola vertex lies within ``tol`` px of ``d``."""
    xl, yl, xr, yr = (np.float32(v) for v in m[:4])
    x, y, yri = rround(xl), rround(yl), rround(yr)
    d = np.float32(xl - xr)
    d0 = rround(d)
    a = _zncc_window(l, x, y)
    if a is None:
        return False
    z = np.full(5, -np.inf)
    for k in range(5):
        b = _zncc_window(r, x - d0 - (k - 2), yri)
        if b is not None:
            z[k] = float(a @ b) / math.sqrt(float(a @ a) * float(b @ b))
    best = int(np.argmax(z))
    if best in (0, 4):
        return False
    c0, c1, c2 = z[best - 1], z[best], z[best + 1]
    den = c0 - 2.0 * c1 + c2
    if not (np.isfinite(c0) and np.isfinite(c2) and den < 0):
        return False
    off = min(max(0.5 * (c0 - c2) / den, -0.5), 0.5)
    return abs(d0 + (best - 2) + off - float(d)) <= tol


def channel_curves(
    img: np.ndarray, sigma: float, p: dict[str, Any], lg: np.ndarray | None = None
) -> dict[str, Any]:
    """LoG (or the given response), zero crossings, tracking, segments and R-tables."""
    L = log_filter(img, sigma).astype(np.float32) if lg is None else lg
    zc = zero_crossings(L)
    min_len = max(p["min_len"], math.ceil(p["min_len_sigmas"] * sigma))
    tr = track(zc, p, min_len)
    w = L.shape[1]
    segs = [segment_info(s, zc["theta"], w) for s in tr["segments"]]
    rts = [rtable(s, zc["theta"], p["n_theta_bins"]) for s in segs]
    return {"sigma": sigma, "log": L, "zc": zc, "labels": tr["labels"], "segs": segs, "rts": rts}


def _full(v: float, s: np.float32) -> float:
    """Channel coordinate -> full resolution (pixel centres of a 2x2 decimation)."""
    return float(s * np.float32(v) + np.float32(0.5) * (s - np.float32(1)))


def mcgm_match(
    left: np.ndarray,
    right: np.ndarray,
    d_min: int,
    d_max: int,
    params: dict[str, Any] | None = None,
) -> np.ndarray:
    """The whole channel: ``(N, 6)`` float32 ``[xl, yl, xr, yr, score, channel]``."""
    p = {**DEFAULTS, **(params or {})}
    fh, fw = left.shape
    half_l = decimate2(left) if any(s >= p["half_res_sigma"] for s in p["sigmas"]) else None
    half_r = decimate2(right) if half_l is not None else None
    prior: np.ndarray | None = None
    per_channel: list[tuple[int, list[tuple[float, ...]]]] = []
    for ci, sigma in enumerate(p["sigmas"]):
        scale = 2 if sigma >= p["half_res_sigma"] else 1
        sig = sigma / 2 if scale == 2 else sigma
        li = half_l if scale == 2 else left
        ri = half_r if scale == 2 else right
        cl = channel_curves(li, sig, p)
        cr = channel_curves(ri, sig, p)
        s = np.float32(scale)
        lo_c = math.floor(np.float32(d_min) / s)
        hi_c = math.ceil(np.float32(d_max) / s)
        full = (lo_c, hi_c) if lo_c <= hi_c else None
        width = np.float32(p["prior_width_sigmas"]) * np.float32(sig)
        if prior is None:
            wins = [full] * len(cl["segs"])
        else:
            radius = math.ceil(
                np.float32(p["prior_radius_sigmas"]) * np.float32(p["sigmas"][ci - 1])
            )
            sp = spread_prior(prior, radius)
            wins = []
            for sg in cl["segs"]:
                cx = s * sg["x"].astype(np.float32) + np.float32(0.5) * (s - np.float32(1))
                cy = s * sg["y"].astype(np.float32) + np.float32(0.5) * (s - np.float32(1))
                fx = np.minimum([rround(v) for v in cx], fw - 1)
                fy = np.minimum([rround(v) for v in cy], fh - 1)
                v = sp[fy, fx]
                v = np.sort(v[np.isfinite(v)] / s)
                if len(v) == 0:
                    wins.append(full)
                    continue
                dmed = v[(len(v) - 1) // 2]
                lo = max(math.floor(dmed - width), lo_c)
                hi = min(math.ceil(dmed + width), hi_c)
                wins.append((lo, hi) if lo <= hi else None)
        cands = candidates(cl["segs"], cl["rts"], cr["segs"], cr["zc"]["theta"], wins, p)
        adj = knn_graph(cl["segs"], p["knn"], np.float32(p["r_graph"]) / s)
        rows = association_rows(cands, cl["segs"], adj, p)
        chosen = solve(cands, rows, p)
        # Decomposition.
        w = li.shape[1]
        min_cos = math.sin(math.radians(p["horiz_skip_deg"]))
        half = np.float32(0.5) * CHANNEL_WIDTH_SIGMAS * np.float32(sig)
        ms: list[tuple[float, ...]] = []
        for c in chosen:
            cd = cands[c]
            sg = cl["segs"][cd["left"]]
            for i, x, y in zip(sg["pixels"], sg["x"], sg["y"], strict=True):
                if abs(math.cos(float(cl["zc"]["theta"].ravel()[i]))) < min_cos:
                    continue
                xp = cl["zc"]["xsub"][y, x]
                target = xp - np.float32(cd["tx"])
                x0 = max(math.floor(target - half), 0)
                x1 = min(math.ceil(target + half), w - 1)
                best = None
                for xq in range(x0, x1 + 1):
                    if cr["labels"][y, xq] != cd["right"]:
                        continue
                    dist = abs(cr["zc"]["xsub"][y, xq] - target)
                    if dist <= half and (best is None or dist < best[0]):
                        best = (dist, xq)
                if best is not None:
                    xq = best[1]

                    ms.append(
                        (
                            _full(xp, s),
                            _full(y, s),
                            _full(cr["zc"]["xsub"][y, xq], s),
                            _full(y, s),
                            cd["score"],
                            ci,
                        )
                    )
        per_channel.append((scale, ms))
        if prior is None:
            prior = np.full((fh, fw), np.nan, np.float32)
        for mm in ms:
            xx, yy = rround(mm[0]), rround(mm[1])
            if 0 <= xx < fw and 0 <= yy < fh:
                prior[yy, xx] = np.float32(mm[0]) - np.float32(mm[2])
    taken = np.zeros((fh, fw), bool)
    combined: list[tuple[float, ...]] = []
    for scale, ms in reversed(per_channel):
        if scale != 1:
            continue
        mine = []
        for mm in ms:
            x, y = rround(mm[0]), rround(mm[1])
            if not (0 <= x < fw and 0 <= y < fh):
                continue
            x0, x1 = max(x - p["fill_radius"], 0), min(x + p["fill_radius"], fw - 1)
            if taken[y, x0 : x1 + 1].any():
                continue
            combined.append(mm)
            mine.append((y, x))
        for y, x in mine:
            taken[y, x] = True
    arr = np.array(combined, np.float32).reshape(-1, 6)
    # Exact repeats of a correspondence (one crossing on two curve pixels) once, the first kept.
    _, first = np.unique(arr[:, :4], axis=0, return_index=True)
    arr = arr[np.sort(first)]
    keep = edge_filters(
        left.astype(np.float32), right.astype(np.float32), arr[:, :4], p, (d_min, d_max)
    )
    return arr[keep]
