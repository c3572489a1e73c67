"""NumPy reference of the Hopfield channel (rust/core/src/matching/hopfield), written for clarity.

* :func:`moravec` / :func:`interest_points` -- bit-exact oracle of the interest operator (same
  float32 summation order as the Rust kernel: horizontal 5-sums left to right, then vertical);
* :func:`zncc_curve` -- direct float64 ZNCC of a region along a row;
* :func:`candidates` -- ZNCC peaks, depth-edge verdicts, parabola offsets (row mode);
* :func:`build_weights`, :func:`run_dynamics` -- the network, with the same SplitMix64 order;
* :func:`hopfield_match` / :func:`best_match` -- the whole pipeline.
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

BORDER = 3
SIM_RADIUS = 3
MIN_WINDOW_STD = 1e-3
MASK64 = (1 << 64) - 1
# (x0, x1, y0, y1): full 7x7, then the half-windows left, right, top, bottom.
REGIONS = [(-3, 3, -3, 3), (-3, -1, -3, 3), (1, 3, -3, 3), (-3, 3, -3, -1), (-3, 3, 1, 3)]

DEFAULTS = {
    "rel_threshold": 1e-3,
    "nms_half": 1,
    "tile": 64,
    "floor_rel": 1e-4,
    "s_min": 0.8,
    "k_cand": 8,
    "A": 3.0,
    "B": 1.5,
    "D": 1.0,
    "theta": 0.6,
    "nbr_half": 20,
    "compat_theta": 2.0,
    "compat_slope": 2.0,
    "compat_grad": 0.05,
    "s_init": 0.8,
    "init_best": True,
    "max_sweeps": 100,
    "seed": 0,
    "edge_test": True,
    "edge_tol": 1,
    "edge_margin": 0.0,
    "edge_penalty": 0.5,
    "centre_tol": 0.05,
    "rescue_min": 3,
    "rescue_med": 0.75,
    "fallback": True,
    "fallback_alt_support": 2.0,
    "fallback_min_support": 0.5,
    "fallback_group": True,
    "min_agree": 8,
    "agree_tol": 1,
    "agree_share": 0.8,
    "min_agree_sparse": 2,
    "subpixel": True,
}


def _box5(s: np.ndarray) -> np.ndarray:
    """5x5 sums at every pixel whose window fits, same order as Rust; 0 elsewhere."""
    h, w = s.shape
    hs = np.zeros_like(s)
    acc = s[:, 0 : w - 4].copy()
    for k in range(1, 5):
        acc = acc + s[:, k : w - 4 + k]
    hs[:, 2 : w - 2] = acc
    out = np.zeros_like(s)
    acc = hs[0 : h - 4, :].copy()
    for k in range(1, 5):
        acc = acc + hs[k : h - 4 + k, :]
    out[2 : h - 2, :] = acc
    return out


def moravec(img: np.ndarray) -> np.ndarray:
    """Moravec interest map ``min(S_h, S_v, S_d, S_a)`` (float32), 0 within 3 px of the border."""
    a = img.astype(np.float32)
    h, w = a.shape
    out = np.zeros((h, w), dtype=np.float32)
    if w < 2 * BORDER + 1 or h < 2 * BORDER + 1:
        return out
    sums = []
    for sx, sy in ((1, 0), (0, 1), (1, 1), (1, -1)):
        sq = np.zeros_like(a)
        ys = slice(max(0, -sy), h - max(0, sy))
        ys2 = slice(max(0, -sy) + sy, h - max(0, sy) + sy)
        d = a[ys, 0 : w - sx] - a[ys2, sx:w]
        sq[ys, 0 : w - sx] = d * d
        sums.append(_box5(sq))
    m = np.minimum(np.minimum(sums[0], sums[1]), np.minimum(sums[2], sums[3]))
    out[BORDER : h - BORDER, BORDER : w - BORDER] = m[BORDER : h - BORDER, BORDER : w - BORDER]
    return out


def interest_points(
    img: np.ndarray,
    rel_threshold: float = 1e-3,
    nms_half: int = 1,
    tile: int = 64,
    floor_rel: float = 1e-4,
) -> tuple[np.ndarray, np.ndarray]:
    """``(xy (N, 2) int, values (N,) float32)`` in raster order."""
    m = moravec(img)
    h, w = m.shape
    mx = np.float32(m.max())
    if mx <= 0:
        return np.zeros((0, 2), np.int64), np.zeros(0, np.float32)
    t = tile if tile > 0 else max(h, w)
    ty, tx = -(-h // t), -(-w // t)
    pad = np.zeros((ty * t, tx * t), np.float32)
    pad[:h, :w] = m
    tmax = pad.reshape(ty, t, tx, t).max(axis=(1, 3))
    local = np.repeat(np.repeat(tmax, t, axis=0), t, axis=1)[:h, :w]
    thr = np.maximum(local * np.float32(rel_threshold), mx * np.float32(floor_rel))
    r = nms_half
    pad = np.pad(m, r, constant_values=-np.inf)
    keep = (m > 0) & (m >= thr)
    keep[:BORDER, :] = keep[h - BORDER :, :] = False
    keep[:, :BORDER] = keep[:, w - BORDER :] = False
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            if dx == 0 and dy == 0:
                continue
            nb = pad[r + dy : r + dy + h, r + dx : r + dx + w]
            earlier = dy < 0 or (dy == 0 and dx < 0)
            keep &= (m > nb) if earlier else (m >= nb)
    ys, xs = np.nonzero(keep)
    return np.stack([xs, ys], axis=1), m[ys, xs]


def zncc_curve(
    left: np.ndarray, right: np.ndarray, region: int, x: int, y: int, yr: int, d_hi: int
) -> np.ndarray:
    """ZNCC of ``region`` around left (x, y) against right (x - d, yr), d = 0..d_hi (float64)."""
    x0, x1, y0, y1 = REGIONS[region]
    n = (x1 - x0 + 1) * (y1 - y0 + 1)
    min_n2 = n * MIN_WINDOW_STD**2
    t = left[y + y0 : y + y1 + 1, x + x0 : x + x1 + 1].astype(np.float64)
    t = t - t.mean()
    tn = float((t * t).sum())
    out = np.zeros(d_hi + 1)
    if tn < min_n2:
        return out
    # Row d: the right window at x - d, flattened (one contiguous row each, so every row sums
    # in the same order as one window's ``.sum()``: the values of a loop over d, bit for bit).
    band = right[yr + y0 : yr + y1 + 1, x - d_hi + x0 : x + x1 + 1]
    wins = sliding_window_view(band, (y1 - y0 + 1, x1 - x0 + 1))[0, ::-1]
    r = np.ascontiguousarray(wins, dtype=np.float64).reshape(d_hi + 1, n)
    r = r - r.mean(axis=1, keepdims=True)
    rn = (r * r).sum(axis=1)
    num = (t.reshape(1, n) * r).sum(axis=1)
    ok = rn >= min_n2
    out[ok] = num[ok] / np.sqrt(tn * rn[ok])
    return out


def _argmax(c: np.ndarray, lo: int, hi: int) -> int | None:
    seg = c[lo : hi + 1]
    k = int(np.argmax(seg))
    return lo + k if seg[k] > 0 else None


def _parabola(a: float, b: float, c: float) -> float:
    den = a - 2 * b + c
    if den >= 0:
        return 0.0
    return float(np.clip(0.5 * (a - c) / den, -0.5, 0.5))


def _textured(img: np.ndarray, x: int, y: int) -> bool:
    """The 7x7 window centred at ``(x, y)`` is textured: ZNCC with it is defined."""
    win = img[y - 3 : y + 4, x - 3 : x + 4].astype(np.float64)
    return float(((win - win.mean()) ** 2).sum()) >= win.size * MIN_WINDOW_STD**2


def candidates(left: np.ndarray, right: np.ndarray, d_min: int, d_max: int, p: dict) -> list[dict]:
    """Row-mode candidate neurons, grouped by point, best ZNCC first."""
    xy, _ = interest_points(left, p["rel_threshold"], p["nms_half"], p["tile"], p["floor_rel"])
    w = left.shape[1]
    out = []
    for i, (x, y) in enumerate(xy.tolist()):
        d_hi = min(d_max, x - SIM_RADIUS)
        if x + SIM_RADIUS >= w or d_hi < d_min:
            continue
        curves = [zncc_curve(left, right, k, x, y, y, d_hi) for k in range(5)]
        full = curves[0]
        best = [_argmax(c, d_min, d_hi) for c in curves[1:]]
        cands = []
        for d in range(d_min, d_hi + 1):
            c = full[d]
            ok_lo = d == d_min or c >= full[d - 1]
            ok_hi = d == d_hi or c > full[d + 1]
            # an undefined ZNCC (a textureless window) reads 0 but is no candidate at any s_min;
            # the window tests come last, as they cost the most
            peak = c >= p["s_min"] and ok_lo and ok_hi
            if peak and _textured(left, x, y) and _textured(right, x - d, y):
                lo, hi = max(d - p["edge_tol"], d_min), min(d + p["edge_tol"], d_hi)
                halves_fail = sum(
                    (0 if b is not None and c[lo : hi + 1].max() >= c[b] - p["edge_margin"] else 1)
                    << k
                    for k, (b, c) in enumerate(zip(best, curves[1:], strict=True))
                )
                lw = left[y - 3 : y + 4, x - 3 : x + 4].astype(np.float64)
                rw = right[y - 3 : y + 4, x - d - 3 : x - d + 4].astype(np.float64)
                lc = float(left[y, x]) - lw.mean()
                rc = float(right[y, x - d]) - rw.mean()
                centre_ok = abs(lc - rc) <= p["centre_tol"]
                sub = (
                    _parabola(full[d - 1], full[d], full[d + 1])
                    if p["subpixel"] and 1 <= d < d_hi
                    else 0.0
                )
                cands.append(
                    {
                        "point": i,
                        "xl": x,
                        "yl": y,
                        "xr": x - d,
                        "yr": y,
                        "sim": float(c),
                        "edge_ok": halves_fail == 0 and centre_ok,
                        "halves_fail": halves_fail,
                        "centre_ok": centre_ok,
                        "sub": sub,
                    }
                )
        cands.sort(key=lambda n: (-n["sim"], n["xr"]))
        out.extend(cands[: p["k_cand"]])
    return out


def _compat(dist: float, theta: float, slope: float) -> float:
    return 2.0 / (1.0 + np.exp(slope * (dist - theta))) - 1.0


def build_weights(neurons: list[dict], p: dict) -> list[list[tuple[int, float]]]:
    """Adjacency lists ``[(b, T_ab)]`` of the symmetric weight matrix."""
    half = p["nbr_half"]
    points = sorted({n["point"] for n in neurons})
    pxy = {}
    members: dict[int, list[int]] = {}
    same_right: dict[tuple[int, int], list[int]] = {}  # neurons by right pixel, in order
    for a, n in enumerate(neurons):
        pxy[n["point"]] = (n["xl"], n["yl"])
        members.setdefault(n["point"], []).append(a)
        same_right.setdefault((n["xr"], n["yr"]), []).append(a)
    nbrs = {
        q: [
            r
            for r in points
            if r != q and abs(pxy[r][0] - pxy[q][0]) <= half and abs(pxy[r][1] - pxy[q][1]) <= half
        ]
        for q in points
    }
    rows: list[list[tuple[int, float]]] = []
    for a, na in enumerate(neurons):
        row = []
        for b in members[na["point"]]:
            if b != a:
                row.append((b, -p["B"]))
        for b in same_right[(na["xr"], na["yr"])]:
            if neurons[b]["point"] != na["point"]:
                row.append((b, -p["B"]))
        q = na["point"]
        for r in nbrs[q]:
            norm = p["A"] / max(len(nbrs[q]), len(nbrs[r]), 1)
            # The crossing grows with the Chebyshev distance of the two points (f32 parameters
            # widened to f64, as in Rust).
            cheb = max(abs(pxy[r][0] - pxy[q][0]), abs(pxy[r][1] - pxy[q][1]))
            ctheta = (
                float(np.float32(p["compat_theta"])) + float(np.float32(p["compat_grad"])) * cheb
            )
            for b in members[r]:
                nb = neurons[b]
                if (nb["xr"], nb["yr"]) == (na["xr"], na["yr"]):
                    continue
                ex = (na["xl"] - na["xr"]) - (nb["xl"] - nb["xr"])
                ey = (na["yl"] - na["yr"]) - (nb["yl"] - nb["yr"])
                slope = float(np.float32(p["compat_slope"]))
                c = np.float32(_compat(np.sqrt(ex * ex + ey * ey), ctheta, slope))
                row.append((b, float(np.float32(norm) * c)))
        rows.append(row)
    return rows


def splitmix_shuffle(order: list[int], state: int) -> int:
    """In-place Fisher-Yates with SplitMix64 (mirrors the Rust generator); returns the state."""
    for i in range(len(order) - 1, 0, -1):
        state = (state + 0x9E3779B97F4A7C15) & MASK64
        z = state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK64
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK64
        z ^= z >> 31
        j = z % (i + 1)
        order[i], order[j] = order[j], order[i]
    return state


def run_dynamics(
    rows: list[list[tuple[int, float]]],
    inp: np.ndarray,
    init: np.ndarray,
    seed: int,
    max_sweeps: int,
) -> tuple[np.ndarray, list[float]]:
    """Asynchronous threshold dynamics; returns the final state and the energy trace."""
    m = len(rows)
    v = init.astype(np.int8).copy()
    u = inp.astype(np.float64).copy()
    for a in range(m):
        if v[a]:
            for b, t in rows[a]:
                u[b] += t

    def energy() -> float:
        on = v == 1
        return float(-(0.5 * (u[on] - inp[on]) + inp[on]).sum())

    trace = [energy()]
    order = list(range(m))
    state = seed
    for _ in range(max_sweeps):
        if m == 0:
            break
        state = splitmix_shuffle(order, state)
        flips = 0
        for a in order:
            new = 1 if u[a] > 0 else (0 if u[a] < 0 else v[a])
            if new != v[a]:
                v[a] = new
                flips += 1
                s = 1.0 if new else -1.0
                for b, t in rows[a]:
                    u[b] += s * t
        trace.append(energy())
        if flips == 0:
            break
    return v, trace


def _fallback(neurons: list[dict], rows: list[list[tuple[int, float]]], v: np.ndarray, p: dict):
    """Final selection's fallback: a point without an active candidate gets its best one back
    when an active alternative has support < fallback_alt_support (or, with none active, the
    best has support >= fallback_min_support) and no other point's active neuron holds the
    right pixel. Support = sum of the positive weights from active neurons. With fallback_group,
    also an unsupported point whose one candidate passed the edge test, when more than
    min_agree such points (itself included) in its window agree with it."""
    if not p["fallback"]:
        return v
    out = v.copy()
    support = [sum(t for b, t in row if t > 0 and v[b] == 1) for row in rows]
    held: dict[tuple[int, int], set[int]] = {}
    for a in np.nonzero(v)[0].tolist():
        held.setdefault((neurons[a]["xr"], neurons[a]["yr"]), set()).add(neurons[a]["point"])
    groups: dict[int, list[int]] = {}
    for a, n in enumerate(neurons):
        groups.setdefault(n["point"], []).append(a)
    weak: dict[int, bool] = {}
    for q, g in groups.items():
        a = g[0]  # best ZNCC first
        if v[a]:
            continue
        alt = [support[b] for b in g[1:] if v[b]]
        weak[q] = (
            max(alt) < float(np.float32(p["fallback_alt_support"]))
            if alt
            else support[a] >= float(np.float32(p["fallback_min_support"]))
        )
    if p["fallback_group"]:
        # Thin surfaces: unsupported points with one edge-clean candidate fall back when more
        # than min_agree of them (itself included) in the window agree within agree_tol.
        lone = [q for q, w in weak.items() if not w and len(groups[q]) == 1]
        lone = [q for q in lone if neurons[groups[q][0]]["edge_ok"]]
        half = p["nbr_half"]
        coherent = []
        for q in lone:
            n = neurons[groups[q][0]]
            d = n["xl"] - n["xr"]
            agree = 0
            for r in lone:
                m = neurons[groups[r][0]]
                near = abs(m["xl"] - n["xl"]) <= half and abs(m["yl"] - n["yl"]) <= half
                agree += near and abs((m["xl"] - m["xr"]) - d) <= p["agree_tol"]
            if agree > p["min_agree"]:
                coherent.append(q)
        for q in coherent:
            weak[q] = True
    for q, w in weak.items():
        a = groups[q][0]
        free = held.get((neurons[a]["xr"], neurons[a]["yr"]), set()) <= {q}
        if w and free:
            out[a] = 1
    return out


def _rescue(neurons: list[dict], chosen: list[int], p: dict) -> list[int]:
    """Edge-test survivors of ``chosen`` with the side rescue iterated to a fixed point: a match
    failing only half-window tests is accepted when, for every failing half (bit k: left,
    right, top, bottom), >= rescue_min accepted matches lie on that side in the window, all
    agree within agree_tol and their median sub-pixel disparity is within rescue_med."""
    if not p["edge_test"]:
        return list(chosen)
    ok = {a: neurons[a]["edge_ok"] for a in chosen}
    if p["rescue_min"] == 0:
        return [a for a in chosen if ok[a]]
    half = p["nbr_half"]
    med_tol = np.float32(p["rescue_med"])
    while True:
        acc = [b for b in chosen if ok[b]]
        added = []
        for a in chosen:
            n = neurons[a]
            if ok[a] or not n["centre_ok"] or n["halves_fail"] == 0:
                continue
            d = n["xl"] - n["xr"]
            dsub = np.float32(d) + np.float32(n["sub"])
            good = True
            for k in range(4):
                if not (n["halves_fail"] >> k) & 1:
                    continue
                side = []
                for b in acc:
                    m = neurons[b]
                    if abs(m["xl"] - n["xl"]) > half or abs(m["yl"] - n["yl"]) > half:
                        continue
                    dx, dy = m["xl"] - n["xl"], m["yl"] - n["yl"]
                    if (dx < 0, dx > 0, dy < 0, dy > 0)[k]:
                        side.append(m)
                dm = [m["xl"] - m["xr"] for m in side]
                if (
                    len(side) < p["rescue_min"]
                    or any(abs(v - d) > p["agree_tol"] for v in dm)
                    or abs(
                        np.float32(
                            np.median(
                                np.array(
                                    [
                                        np.float32(v) + np.float32(m["sub"])
                                        for v, m in zip(dm, side, strict=True)
                                    ],
                                    dtype=np.float32,
                                )
                            )
                        )
                        - dsub
                    )
                    > med_tol
                ):
                    good = False
                    break
            if good:
                added.append(a)
        if not added:
            return [a for a in chosen if ok[a]]
        for a in added:
            ok[a] = True


def _finish(neurons: list[dict], chosen: list[int], p: dict) -> np.ndarray:
    surv = _rescue(neurons, chosen, p)
    half = p["nbr_half"]
    out = []
    for a in surv:
        n = neurons[a]
        d = n["xl"] - n["xr"]
        near = [
            b
            for b in surv
            if b != a
            and abs(neurons[b]["xl"] - n["xl"]) <= half
            and abs(neurons[b]["yl"] - n["yl"]) <= half
        ]
        agree = sum(
            1 for b in near if abs((neurons[b]["xl"] - neurons[b]["xr"]) - d) <= p["agree_tol"]
        )
        sparse_ok = (
            p["agree_share"] > 0
            and agree >= p["min_agree_sparse"]
            and agree >= np.float32(p["agree_share"]) * np.float32(len(near))
        )
        if p["edge_test"] and agree < p["min_agree"] and not sparse_ok:
            continue
        out.append([n["xl"], n["yl"], n["xl"] - (d + n["sub"]), n["yr"], n["sim"]])
    return np.array(out, dtype=np.float32).reshape(-1, 5)


def hopfield_match(
    left: np.ndarray, right: np.ndarray, d_min: int, d_max: int, **params: object
) -> tuple[np.ndarray, list[float]]:
    """``(matches (N, 5) [xl, yl, xr, yr, score], energy_trace)``; row mode, rectified input
    (C.5 disambiguation reduces to the highest ZNCC, as dy = 0 for every candidate)."""
    p = {**DEFAULTS, **params}
    neurons = candidates(left, right, d_min, d_max, p)
    rows = build_weights(neurons, p)
    inp = np.array(
        [
            float(
                np.float32(p["D"]) * np.float32(n["sim"])
                - np.float32(p["theta"])
                - np.float32(p["edge_penalty"] if p["edge_test"] and not n["edge_ok"] else 0.0)
            )
            for n in neurons
        ]
    )
    # Preset (C.4): ZNCC >= s_init, with init_best only each point's first (best) candidate.
    first = [a == 0 or neurons[a - 1]["point"] != n["point"] for a, n in enumerate(neurons)]
    init = np.array(
        [
            n["sim"] >= p["s_init"] and (f or not p["init_best"])
            for n, f in zip(neurons, first, strict=True)
        ],
        dtype=np.int8,
    )
    v, trace = run_dynamics(rows, inp, init, int(p["seed"]), int(p["max_sweeps"]))
    v = _fallback(neurons, rows, v, p)
    best: dict[int, int] = {}
    for a in np.nonzero(v)[0].tolist():
        q = neurons[a]["point"]
        if q not in best or neurons[a]["sim"] > neurons[best[q]]["sim"]:
            best[q] = a
    by_right: dict[tuple[int, int], int] = {}
    for a in best.values():
        key = (neurons[a]["xr"], neurons[a]["yr"])
        if key not in by_right or neurons[a]["sim"] > neurons[by_right[key]]["sim"]:
            by_right[key] = a
    chosen = sorted(by_right.values())
    return _finish(neurons, chosen, p), trace


def best_match(
    left: np.ndarray, right: np.ndarray, d_min: int, d_max: int, **params: object
) -> np.ndarray:
    """The reference without the network: best candidate of every point, same filters."""
    p = {**DEFAULTS, **params}
    neurons = candidates(left, right, d_min, d_max, p)
    chosen, seen = [], set()
    for a, n in enumerate(neurons):
        if n["point"] not in seen:
            seen.add(n["point"])
            chosen.append(a)
    return _finish(neurons, chosen, p)
