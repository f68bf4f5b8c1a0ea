"""Pareto front and knee of measured (cost, error) points — pure functions.

A point is any mapping (the result dicts of bench/results/accuracy.json) with a
cost key (default "time_s", seconds) and an error key (default "flip"). Lower is
better on both axes.
"""
import math

__all__ = ["pareto_front", "knee", "usable"]


def number(point, key):
    """point[key] as a finite float, or None when it is missing / null / NaN / inf / not a number."""
    try:
        v = point.get(key)
    except AttributeError:
        return None
    if v is None or isinstance(v, bool):
        return None
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def usable(points, cost="time_s", error="flip"):
    """The points that have a finite cost and a finite error, in input order."""
    return [p for p in points if number(p, cost) is not None and number(p, error) is not None]


def pareto_front(points, cost="time_s", error="flip"):
    """The points no other point dominates, sorted by increasing cost (so
    decreasing error).

    q dominates p when q[cost] <= p[cost] and q[error] <= p[error] and q is
    strictly lower on at least one of the two. Points whose cost or error is
    missing, None or not finite are skipped (not on the front).
    Ties: of several points with an identical (cost, error) pair only the first
    in input order is kept, so the front has one point per position; with equal
    cost only the lowest error survives, with equal error only the lowest cost.
    Returns a new list of the original point objects.
    """
    cands = [(number(p, cost), number(p, error), i, p) for i, p in enumerate(points)]
    cands = [c for c in cands if c[0] is not None and c[1] is not None]
    cands.sort(key=lambda c: (c[0], c[1], c[2]))  # cost, then error, then input order
    front = []
    best = math.inf  # lowest error among the cheaper (or equally cheap) points seen so far
    for _, e, _, p in cands:
        if e < best:  # strictly better error than everything at lower-or-equal cost
            front.append(p)
            best = e
    return front


def knee(front, cost="time_s", error="flip"):
    """The knee of a Pareto front: the point farthest from the straight line
    joining the front's two ends, measured in (log10 cost, error) space with
    both axes rescaled to span [0, 1] over the front (so the answer does not
    depend on the units of either axis, and a decade of cost weighs as much
    as the whole error range).

    front: points as returned by pareto_front (any order; re-sorted by cost).
    Costs must be > 0 (log scale). Returns the knee point, or None when the
    front has fewer than 3 usable points (the ends are never the knee) or all
    interior points lie on the line. Ties in distance go to the cheaper point.
    """
    pts = sorted(usable(front, cost, error), key=lambda p: (number(p, cost), number(p, error)))
    if len(pts) < 3:
        return None
    for p in pts:
        if number(p, cost) <= 0:
            raise ValueError(f"knee: cost {cost}={p.get(cost)!r} must be > 0 for a log scale (point {p!r})")
    xs = [math.log10(number(p, cost)) for p in pts]
    ys = [number(p, error) for p in pts]

    def scaled(v):
        lo, hi = min(v), max(v)
        span = hi - lo
        return [(x - lo) / span if span > 0 else 0.0 for x in v]

    xs, ys = scaled(xs), scaled(ys)
    x0, y0, x1, y1 = xs[0], ys[0], xs[-1], ys[-1]
    dx, dy = x1 - x0, y1 - y0
    length = math.hypot(dx, dy)
    if length == 0:
        return None
    best, best_d = None, 0.0
    for i in range(1, len(pts) - 1):
        d = abs(dy * (xs[i] - x0) - dx * (ys[i] - y0)) / length  # distance to the line
        if d > best_d + 1e-12:
            best, best_d = pts[i], d
    return best
