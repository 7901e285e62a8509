"""Time one top-down frame of a 20 m x 20 m house (budget: under 10 ms per frame).

Draws the frame the task renders: robots (1 and 8) over 12 translucent markers (start,
goal and 10 path waypoints), with ``TopDownRenderer.draw`` (numpy, bounding-box masks) and,
for comparison, with Pillow ``ImageDraw`` on the same cached floor (translucent markers as
an alpha-composited overlay), and prints the median and 90th percentile over many frames.

Then times what a user calls: ``env.render()`` of a ``PointNavEnv`` on the same house with
``visualize_goal`` and ``visualize_path`` on (the robot, start, goal and 10 waypoints), one
frame after each step of the oracle (only ``render`` is timed). It also reports the cost of
the markers on ``env.step`` (visualisation off, goal only, goal and path).

Run::

    python benchmarks/bench_render.py
    python benchmarks/bench_render.py --frames 500 --pixels-per-meter 40
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable, Sequence

import numpy as np
from PIL import Image, ImageDraw

from pointnav_core.render.top_down import (
    GOAL_COLOR,
    ROBOT_PALETTE,
    START_COLOR,
    WAYPOINT_COLOR,
    Marker,
    RobotGlyph,
    TopDownRenderer,
    contrast_color,
)


def house(seed: int):
    """A generated 20 m x 20 m house at 0.1 m/cell (a 200 x 200 grid)."""
    from pointnav_core.scenes import rooms

    return rooms(seed=seed, size=(20.0, 20.0)).floors[0]


def scene_objects(tmap, n_robots: int, seed: int) -> tuple[list[RobotGlyph], list[Marker]]:
    """Robots on usable cells and the task's 12 markers: start, goal, 10 waypoints."""
    rng = np.random.default_rng(seed)
    cells = np.argwhere(tmap.usable(0.18))
    points = tmap.cell_to_world(cells[rng.choice(len(cells), size=n_robots + 2, replace=False)])
    robots = [
        RobotGlyph(position_xy=p, yaw=float(rng.uniform(0, 2 * math.pi)), radius=0.18) for p in points[:n_robots]
    ]
    start, goal = points[n_robots], points[n_robots + 1]
    markers = [
        Marker(position_xy=start, radius=0.5, color=START_COLOR),
        Marker(position_xy=goal, radius=0.5, color=GOAL_COLOR),
    ]
    for t in np.linspace(0.0, 1.0, 10):
        markers.append(Marker(position_xy=start + t * (goal - start), radius=0.1, color=WAYPOINT_COLOR))
    return robots, markers


def pillow_draw(renderer: TopDownRenderer) -> Callable[[Sequence[RobotGlyph], Sequence[Marker]], np.ndarray]:
    """The same frame drawn with Pillow ImageDraw (the alternative that was measured)."""
    floor = Image.fromarray(np.ascontiguousarray(renderer.floor_image)).convert("RGBA")

    def draw(robots: Sequence[RobotGlyph], markers: Sequence[Marker]) -> np.ndarray:
        image = floor.copy()
        if markers:
            overlay = Image.new("RGBA", image.size, (0, 0, 0, 0))
            pen = ImageDraw.Draw(overlay)
            for m in markers:
                (c, r), rad = renderer.world_to_pixel(m.position_xy), m.radius * renderer.scale[0]
                pen.ellipse((c - rad, r - rad, c + rad, r + rad), fill=(*m.color, round(255 * m.alpha)))
            image = Image.alpha_composite(image, overlay)
        pen = ImageDraw.Draw(image)
        for k, g in enumerate(robots):
            (c, r), rad = renderer.world_to_pixel(g.position_xy), g.radius * renderer.scale[0]
            color = g.color or ROBOT_PALETTE[k % len(ROBOT_PALETTE)]
            pen.ellipse((c - rad, r - rad, c + rad, r + rad), fill=color)
            tip = (c + rad * math.cos(g.yaw), r - rad * math.sin(g.yaw))
            pen.line(((c, r), tip), fill=contrast_color(color), width=max(1, round(0.24 * rad)))
        return np.asarray(image.convert("RGB"))

    return draw


def time_frames(draw: Callable[[], np.ndarray], frames: int) -> tuple[float, float]:
    """Median and 90th percentile wall time of one call, in milliseconds."""
    for _ in range(10):
        draw()
    times = np.empty(frames)
    for i in range(frames):
        t0 = time.perf_counter()
        draw()
        times[i] = time.perf_counter() - t0
    return float(np.median(times) * 1e3), float(np.percentile(times, 90) * 1e3)


def env_render_times(seed: int, frames: int, pixels_per_meter: float) -> tuple[float, float]:
    """Median and 90th percentile of ``env.render()`` (ms), one frame per oracle step."""
    from pointnav_core.envs.pointnav import PointNavEnv
    from pointnav_core.policies.oracle import ShortestPathFollower
    from pointnav_core.scenes import rooms

    env = PointNavEnv(
        scene=rooms(seed=seed, size=(20.0, 20.0)),
        task={"visualize_goal": True, "visualize_path": True},
        render_mode="rgb_array",
    )
    env.render_pixels_per_meter = pixels_per_meter
    oracle = ShortestPathFollower(env)
    env.reset(seed=seed)
    env.render()  # the first frame prepares the floor picture (once per env)
    times = np.empty(frames)
    episode = 0
    for i in range(frames):
        _, _, terminated, truncated, _ = env.step(oracle.act())
        if terminated or truncated:
            episode += 1
            env.reset(seed=seed + episode)
        t0 = time.perf_counter()
        env.render()
        times[i] = time.perf_counter() - t0
    return float(np.median(times) * 1e3), float(np.percentile(times, 90) * 1e3)


def env_step_times(seed: int, steps: int) -> list[tuple[str, float]]:
    """Median ``env.step`` time (us) with visualisation off, goal markers only, and both."""
    from pointnav_core.envs.pointnav import PointNavEnv
    from pointnav_core.scenes import rooms

    scene = rooms(seed=seed, size=(20.0, 20.0))
    rows = []
    settings = [("off", {}), ("goal", {"visualize_goal": True}),
                ("goal+path", {"visualize_goal": True, "visualize_path": True})]
    rng = np.random.default_rng(seed)
    actions = rng.uniform(-0.2, 1.0, size=(steps, 2)).astype(np.float32)
    for name, flags in settings:
        env = PointNavEnv(scene=scene, task={**flags, "termination_config": {"max_steps": 10**9}})
        best = math.inf
        for _ in range(3):  # best of three runs: the machines are shared
            env.reset(seed=seed)
            t0 = time.perf_counter()
            for action in actions:
                _, _, terminated, truncated, _ = env.step(action)
                if terminated or truncated:
                    env.reset()
            best = min(best, (time.perf_counter() - t0) / steps * 1e6)
        rows.append((name, best))
    return rows


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=200, help="frames timed per row (default 200)")
    parser.add_argument("--pixels-per-meter", type=float, default=20.0, help="picture scale (default 20)")
    parser.add_argument("--robots", type=int, nargs="+", default=[1, 8], help="robot counts (default 1 8)")
    parser.add_argument("--seed", type=int, default=0, help="house and placement seed (default 0)")
    parser.add_argument("--no-pillow", action="store_true", help="skip the Pillow ImageDraw comparison")
    parser.add_argument("--steps", type=int, default=5000, help="env steps timed per setting (default 5000)")
    args = parser.parse_args(argv)

    tmap = house(args.seed)
    t0 = time.perf_counter()
    renderer = TopDownRenderer(tmap, pixels_per_meter=args.pixels_per_meter)
    setup_ms = (time.perf_counter() - t0) * 1e3
    h, w = renderer.shape
    print(f"map {tmap.shape[0]}x{tmap.shape[1]} cells at {tmap.resolution} m, picture {h}x{w} px "
          f"({args.pixels_per_meter:g} px/m), floor prepared once in {setup_ms:.2f} ms")
    print(f"{'method':<16}{'robots':>7}{'markers':>9}{'median ms':>11}{'p90 ms':>9}")
    pillow = None if args.no_pillow else pillow_draw(renderer)
    for n in args.robots:
        robots, markers = scene_objects(tmap, n, args.seed)
        rows = [("numpy (draw)", lambda: renderer.draw(robots, markers))]
        if pillow is not None:
            rows.append(("Pillow ImageDraw", lambda: pillow(robots, markers)))
        for name, fn in rows:
            median, p90 = time_frames(fn, args.frames)
            print(f"{name:<16}{n:>7}{len(markers):>9}{median:>11.3f}{p90:>9.3f}")

    median, p90 = env_render_times(args.seed, args.frames, args.pixels_per_meter)
    print(f"\nPointNavEnv.render(), 20 m x 20 m house, visualize_goal and visualize_path on, "
          f"{args.frames} frames: median {median:.3f} ms, p90 {p90:.3f} ms")
    print("PointNavEnv.step() by marker setting (best of 3 runs, random actions):")
    for name, us in env_step_times(args.seed, args.steps):
        print(f"  {name:<10}{us:8.1f} us/step")


if __name__ == "__main__":
    main()
