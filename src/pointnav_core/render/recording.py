"""Frames out of environments and onto disk: :func:`render_env`, :func:`record_episode`,
:func:`save_png` and :func:`save_gif`, drawn with :class:`~pointnav_core.render.top_down.TopDownRenderer`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from PIL import Image

from pointnav_core.errors import ArgumentError
from pointnav_core.floor.maps import BoundedCache, TraversableMap
from pointnav_core.render.glyphs import (
    MARKER_COLORS,
    PEDESTRIAN_COLOR,
    Marker,
    RobotGlyph,
    ScanGlyph,
    check_number,
)
from pointnav_core.render.top_down import (
    DEFAULT_PIXELS_PER_METER,
    ROBOT_PALETTE,
    PathArg,
    TopDownRenderer,
)
from pointnav_core.task import TaskState
from pointnav_core.transforms import quat2yaw
from pointnav_core.utils.outputs import atomic_writer

__all__ = ["record_episode", "render_env", "save_gif", "save_png"]


def _check_frame(frame: object, name: str) -> NDArray[np.uint8]:
    arr = np.asarray(frame)
    if arr.dtype != np.uint8 or arr.ndim != 3 or arr.shape[2] != 3 or arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ArgumentError(
            f"{name} must be a uint8 RGB image of shape (H, W, 3), got dtype {arr.dtype} and shape {arr.shape}"
        )
    return np.ascontiguousarray(arr)


def save_png(frame: ArrayLike, path: PathArg) -> None:
    """Write one frame to a PNG file.

    Parameters
    ----------
    frame : ndarray of uint8, shape (H, W, 3)
        An RGB image, e.g. from :meth:`TopDownRenderer.draw`.
    path : str or os.PathLike
        File to write (overwritten if it exists).

    Raises
    ------
    ValueError
        When ``frame`` is not a uint8 (H, W, 3) array.
    """
    image = Image.fromarray(_check_frame(frame, "frame"))
    with atomic_writer(path) as fh:  # whole or not at all
        image.save(fh, format="PNG")


def save_gif(frames: Iterable[ArrayLike], path: PathArg, fps: float = 10) -> None:
    """Write frames to an animated GIF that loops forever.

    Parameters
    ----------
    frames : iterable of ndarray of uint8, shape (H, W, 3)
        At least one RGB frame, all of the same shape.
    path : str or os.PathLike
        File to write (overwritten if it exists).
    fps : float, default 10
        Frames per second, > 0. GIF stores delays in hundredths of a second, so each frame
        lasts ``1000 / fps`` ms rounded to 10 ms (at least 20 ms: most viewers slow shorter
        delays down).

    Raises
    ------
    ValueError
        When there is no frame, a frame is not a uint8 (H, W, 3) array, the frames differ in
        shape, or ``fps`` is not a finite number > 0.
    """
    rate = check_number(fps, "fps", " (frames/s)", low=0.0, strict=True)
    images = []
    first_shape: tuple[int, ...] | None = None
    for i, frame in enumerate(frames):
        arr = _check_frame(frame, f"frames[{i}]")
        if first_shape is None:
            first_shape = arr.shape
        elif arr.shape != first_shape:
            raise ArgumentError(f"frames[{i}] has shape {arr.shape}, but frames[0] has {first_shape}")
        images.append(Image.fromarray(arr))
    if not images:
        raise ArgumentError("frames must hold at least one frame, got none")
    duration = max(20, 10 * round(100.0 / rate))
    with atomic_writer(path) as fh:  # whole or not at all
        images[0].save(
            fh,
            format="GIF",
            save_all=True,
            append_images=images[1:],
            duration=duration,
            loop=0,
            optimize=True,
        )


# ------------------------------------------------------------------------------ environments
def _env_tasks(env: Any) -> list[Any]:
    tasks = getattr(env, "tasks", None)
    if tasks is None:
        task = getattr(env, "task", None)
        return [] if task is None else [task]
    if isinstance(tasks, Mapping):
        return list(tasks.values())
    return list(tasks)


def _renderer_for(
    tmap: TraversableMap, pixels_per_meter: float, renderers: BoundedCache | None
) -> TopDownRenderer:
    """The renderer of ``tmap`` at this scale, taken from ``renderers`` when it has one."""
    if renderers is None:
        return TopDownRenderer(tmap, pixels_per_meter)
    # Keyed by the floor's identity and checked, so a new scene is drawn anew.
    key = (id(tmap), pixels_per_meter)
    renderer = renderers.get_or_create(key, lambda: TopDownRenderer(tmap, pixels_per_meter))
    if renderer.tmap is not tmap:
        renderers.clear()
        renderer = renderers.get_or_create(key, lambda: TopDownRenderer(tmap, pixels_per_meter))
    return renderer


def render_env(
    env: Any, pixels_per_meter: float | None = None, *, renderers: BoundedCache | None = None
) -> NDArray[np.uint8]:
    """Draw an environment from above: one floor, its robots and the tasks' markers.

    Parameters
    ----------
    env : PointNavEnv or a multi-robot env
        Anything with ``scene``, ``backend``, ``robots`` and either ``tasks`` (a sequence,
        or a mapping whose values are tasks) or ``task``.
    pixels_per_meter : float, optional
        Picture scale (> 0). Default: ``env.render_pixels_per_meter`` when the environment
        has that attribute, else :data:`DEFAULT_PIXELS_PER_METER`.
    renderers : BoundedCache, optional
        Where the caller keeps the prepared floor pictures between frames (the envs own one
        each). Without it every call draws the floor anew.

    Returns
    -------
    ndarray of uint8, shape (H, W, 3)
        A new RGB array. It shows the floor of the first task (floor 0 without tasks);
        the env's pedestrians on that floor (``env.crowd``) as grey discs with a heading tick;
        every robot that is present and on that floor as a disc of its spec's ``radius``,
        coloured ``ROBOT_PALETTE[idn % 8]``, with a heading tick (robots whose task has not
        had an episode yet are not placed, and not drawn); and over the floor, below the
        robots, the visible markers of every task on that floor, translucent, coloured by
        kind (:data:`MARKER_COLORS`). A task with a range scan (``"scan"`` observation
        term) has its last readings drawn as rays from its robot, with a dot at each return.

    Notes
    -----
    With ``renderers``, the floor picture is prepared once per floor and scale; a frame then
    costs a copy of it and a few disc masks.

    Examples
    --------
    >>> from pointnav_core.envs.pointnav import PointNavEnv
    >>> env = PointNavEnv(task={"visualize_goal": True}, render_mode="rgb_array")
    >>> _ = env.reset(seed=0)
    >>> frame = env.render()  # calls render_env(env)
    >>> frame.shape, frame.dtype
    ((300, 400, 3), dtype('uint8'))
    >>> render_env(env, pixels_per_meter=10).shape
    (150, 200, 3)
    """
    if pixels_per_meter is None:
        pixels_per_meter = getattr(env, "render_pixels_per_meter", None)
        if pixels_per_meter is None:
            pixels_per_meter = DEFAULT_PIXELS_PER_METER
    ppm = check_number(pixels_per_meter, "pixels_per_meter", " (px/m)", low=0.0, strict=True)
    tasks = _env_tasks(env)
    floor = tasks[0].floor if tasks else 0
    renderer = _renderer_for(env.scene.floors[floor], ppm, renderers)

    markers = _marker_glyphs(tasks, floor)
    robots = _pedestrian_glyphs(env, floor) + _robot_glyphs(env, tasks, floor)
    return renderer.draw(robots, markers, _scan_glyphs(env.backend, tasks, floor))


def _pedestrian_glyphs(env: Any, floor: int) -> list[RobotGlyph]:
    """The env's pedestrians on ``floor`` (its ``crowd``), grey, facing where they walk."""
    crowd = getattr(env, "crowd", None)
    if crowd is None or crowd.floor != floor:
        return []
    return [
        RobotGlyph(position_xy=(x, y), yaw=yaw, radius=r, color=PEDESTRIAN_COLOR)
        for (x, y), yaw, r in zip(crowd.positions.tolist(), crowd.headings.tolist(), crowd.radius.tolist())
    ]


def _marker_glyphs(tasks: list[Any], floor: int) -> list[Marker]:
    """The visible markers of the tasks on ``floor``, coloured by kind."""
    markers = []
    for task in tasks:
        if task.floor != floor:
            continue
        for marker in task.markers:
            if marker.visible:
                markers.append(
                    Marker(position_xy=marker.position[:2], radius=marker.radius, color=MARKER_COLORS[marker.kind])
                )

    return markers


def _robot_glyphs(env: Any, tasks: list[Any], floor: int) -> list[RobotGlyph]:
    """The placed robots present on ``floor``, coloured by id."""
    backend = env.backend
    # A robot whose task has never been reset has not been placed (it stands at the origin).
    unplaced = {task.robot_idn for task in tasks if task.state is TaskState.IDLE}
    robots = []
    for idn, spec in enumerate(env.robots):
        if idn in unplaced or not backend.is_present(idn) or backend.get_robot_floor(idn) != floor:
            continue
        position, quat = backend.get_pose(idn)
        robots.append(
            RobotGlyph(
                position_xy=position[:2],
                yaw=float(quat2yaw(quat)),
                radius=spec.radius,
                color=ROBOT_PALETTE[idn % len(ROBOT_PALETTE)],
            )
        )
    return robots


def _scan_glyphs(backend: Any, tasks: list[Any], floor: int) -> list[ScanGlyph]:
    """The last range scan of each task on ``floor`` with a ``"scan"`` term and a robot present."""
    scans = []
    for task in tasks:
        term = task.observation_terms.get("scan")
        last = getattr(term, "last_scan", None)
        if task.floor != floor or last is None or task.state is TaskState.IDLE:
            continue
        if not backend.is_present(task.robot_idn):
            continue
        x, y, yaw, readings = last
        bearings = yaw + term.angles
        ends = np.stack([x + readings * np.cos(bearings), y + readings * np.sin(bearings)], axis=1)
        scans.append(ScanGlyph(origin_xy=(x, y), ends_xy=ends, hit=readings < term.max_range))
    return scans


def record_episode(
    env: Any,
    policy: Callable[[Any], Any],
    path: PathArg | None = None,
    *,
    seed: int | None = None,
    every: int = 1,
    pixels_per_meter: float | None = None,
) -> list[NDArray[np.uint8]]:
    """Run one episode of a Gymnasium-style environment and return its frames.

    Parameters
    ----------
    env : PointNavEnv
        Any environment with ``reset(seed=)``, ``step(action)`` returning five values, and
        what :func:`render_env` reads. Its ``render_mode`` does not matter.
    policy : callable
        ``policy(observation) -> action``, called once per step. For the oracle:
        ``oracle = ShortestPathFollower(env)`` and ``lambda obs: oracle.act()``.
    path : str or os.PathLike, optional
        If given, the frames are also written there as an animated GIF (:func:`save_gif`)
        playing in real time: ``env.metadata["render_fps"] / every`` frames per second.
    seed : int, optional
        Passed to ``env.reset``.
    every : int, default 1
        Keep every ``every``-th step's frame (>= 1); the first and the last frame are
        always kept.
    pixels_per_meter : float, optional
        Picture scale, as in :func:`render_env`.

    Returns
    -------
    list of ndarray of uint8, shape (H, W, 3)
        The frame after reset, then one per kept step, ending with the episode's last.

    Examples
    --------
    >>> from pointnav_core.envs.pointnav import PointNavEnv
    >>> from pointnav_core.policies.oracle import ShortestPathFollower
    >>> env = PointNavEnv(task={"visualize_goal": True, "visualize_path": True})
    >>> oracle = ShortestPathFollower(env)
    >>> frames = record_episode(env, lambda obs: oracle.act(), seed=0, every=10)
    >>> len(frames) > 2, frames[0].shape
    (True, (300, 400, 3))
    """
    if isinstance(every, bool) or int(every) != every or every < 1:
        raise ArgumentError(f"every must be an integer >= 1, got {every!r}")
    every = int(every)
    obs, _ = env.reset(seed=seed)
    renderers = BoundedCache(1)
    frames = [render_env(env, pixels_per_meter, renderers=renderers)]
    steps, done = 0, False
    while not done:
        obs, _, terminated, truncated, _ = env.step(policy(obs))
        steps += 1
        done = bool(terminated or truncated)
        if done or steps % every == 0:
            frames.append(render_env(env, pixels_per_meter, renderers=renderers))
    if path is not None:
        fps = float(getattr(env, "metadata", {}).get("render_fps", 10)) / every
        save_gif(frames, path, fps=fps)
    return frames
