"""The velocity a robot in contact may take: the feasible velocity closest to its command.

Each contact limits the velocity to a half-plane ``n . u >= c`` (``c <= 0``: the robot may
stand still, or back out of an overlap); :func:`closest_feasible` finds the velocity
closest to the command inside all of them.
"""

from __future__ import annotations

__all__ = ["closest_feasible"]


def closest_feasible(
    ux: float, uy: float, limits: list[tuple[float, float, float]]
) -> tuple[float, float]:
    """The velocity closest to (ux, uy) with ``n . u >= c`` for every (nx, ny, c), c <= 0.

    A 2D quadratic programme solved by enumerating active sets (one or two constraints);
    zero is always feasible, since every c <= 0.
    """

    def feasible(vx: float, vy: float) -> bool:
        return all(nx * vx + ny * vy >= c - 1e-12 for nx, ny, c in limits)

    if feasible(ux, uy):
        return ux, uy
    best, best_d = (0.0, 0.0), ux * ux + uy * uy
    for nx, ny, c in limits:
        gap = c - (nx * ux + ny * uy)
        if gap > 0.0:
            vx, vy = ux + gap * nx, uy + gap * ny
            d = gap * gap
            if d < best_d and feasible(vx, vy):
                best, best_d = (vx, vy), d
    for i, (ax, ay, ac) in enumerate(limits):
        for bx, by, bc in limits[i + 1 :]:
            det = ax * by - ay * bx
            if abs(det) < 1e-12:
                continue
            vx = (ac * by - ay * bc) / det
            vy = (ax * bc - ac * bx) / det
            d = (vx - ux) ** 2 + (vy - uy) ** 2
            if d < best_d and feasible(vx, vy):
                best, best_d = (vx, vy), d
    return best
