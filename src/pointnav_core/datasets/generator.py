"""Episode generation with Habitat's PointNav rules, seeded and configurable.

:func:`generate_episodes` follows ``habitat.datasets.pointnav.pointnav_generator``: draw a
goal uniformly over the free space the robot fits in (all floors, by area), reject it when
it stands on a small island, then try up to ``retries_per_goal`` starts drawn on the goal's
floor; a (start, goal) pair is kept when

1. the start is on the goal's floor (we sample it there, so this always holds);
2. a path exists and its geodesic distance lies in ``geodesic_range`` (default [1, 30] m);
3. when the geodesic/euclidean ratio is below ``ratio_threshold`` (1.1), with probability
   ``20 * (ratio - 0.98)**2`` only (Habitat's ``_ratio_sample_rate``), so that straight-line
   episodes are rare;
4. the start is not on a small island: the island containing it (see :func:`island_radius`)
   has a radius of at least ``island_radius_limit`` (Habitat's ``ISLAND_RADIUS_LIMIT``,
   1.5 m).

The start heading is uniform in [0, 2 pi). Every random draw comes from one numpy
``Generator`` seeded with ``seed``, so the same arguments give the same episodes.

With ``pedestrians={...}`` (the envs' argument, :mod:`pointnav_core.crowds.config`) each
episode also records a crowd (:attr:`PointNavEpisode.pedestrians`), drawn as the env draws
one at a reset (:meth:`Crowd.spawn <pointnav_core.crowds.Crowd.spawn>`, on the episode's
floor, clear of the robot's disc at its start) from a second generator of the same seed,
so the episodes themselves are the same with or without pedestrians.
"""

from __future__ import annotations

import hashlib
import math
import weakref
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pointnav_core.crowds import Crowd, make_pedestrians
from pointnav_core.datasets.format import EpisodeDataset, PointNavEpisode
from pointnav_core.datasets.scene_sets import SceneSet, load_scene
from pointnav_core.errors import ArgumentError, SamplingError
from pointnav_core.floor.draw import cell_centre
from pointnav_core.scenes import Scene, robot_radius
from pointnav_core.utils import validation

__all__ = [
    "GeneratorConfig",
    "generate_episodes",
    "generate_split",
    "island_radius",
    "ratio_keep_probability",
    "scene_seed",
]


def ratio_keep_probability(ratio: float) -> float:
    """Probability that a pair with geodesic/euclidean ``ratio`` below the threshold is kept.

    Habitat's ``_ratio_sample_rate``: ``20 * (ratio - 0.98) ** 2`` (clipped to [0, 1]).

    Examples
    --------
    >>> round(ratio_keep_probability(1.0), 6), round(ratio_keep_probability(1.08), 6)
    (0.008, 0.2)
    """
    return min(1.0, 20.0 * (float(ratio) - 0.98) ** 2)


def island_radius(scene: Scene, floor: int, xy: Sequence[float], robot: Any = None) -> float:
    """Radius (m) of the island (free-space component) that contains ``xy``; 0 if none.

    As in habitat-sim's ``PathFinder.island_radius``: the largest distance from the
    island's centroid to any of its points, here its usable cell centres for ``robot``'s
    radius. The islands are the components :meth:`Scene.get_random_point` samples within.
    """
    tmap = scene.floors[floor]
    radius = robot_radius(robot)
    label = int(tmap.component_at(np.asarray(xy, dtype=np.float64)[:2], radius))
    if label == 0:
        return 0.0
    return _island_radii(tmap, radius)[label]


#: Island radii per map and robot radius (maps are immutable; entries die with the map).
_RADII: weakref.WeakKeyDictionary[Any, dict[float, NDArray[np.float64]]] = (
    weakref.WeakKeyDictionary()
)


def _island_radii(tmap: Any, radius: float) -> NDArray[np.float64]:
    """Radius of every component (index = label), cached on the map per robot radius."""
    cache = _RADII.setdefault(tmap, {})
    key = round(radius, 12)
    if key not in cache:
        labels = tmap.components(radius)
        n = int(labels.max())
        radii = np.zeros(n + 1)
        rows, cols = np.nonzero(labels)
        lab = labels[rows, cols]
        centres = tmap.cell_to_world(np.stack([rows, cols], axis=1))
        counts = np.bincount(lab, minlength=n + 1).astype(np.float64)
        cx = np.bincount(lab, centres[:, 0], minlength=n + 1) / np.maximum(counts, 1)
        cy = np.bincount(lab, centres[:, 1], minlength=n + 1) / np.maximum(counts, 1)
        dist = np.hypot(centres[:, 0] - cx[lab], centres[:, 1] - cy[lab])
        np.maximum.at(radii, lab, dist)
        cache[key] = radii
    return cache[key]


@dataclass(frozen=True)
class GeneratorConfig:
    """Habitat's PointNav generation rules, with its defaults.

    Attributes
    ----------
    geodesic_range : (float, float)
        Closed range (m) of the start-goal geodesic distance (Habitat: 1 to 30 m).
    ratio_threshold : float
        Pairs whose geodesic/euclidean ratio is below this are kept with probability
        :func:`ratio_keep_probability` (Habitat: 1.1).
    island_radius_limit : float
        Starts on an island of smaller radius (m) are rejected (Habitat: 1.5 m).
    retries_per_goal : int
        Starts tried for one goal before a new goal is drawn (Habitat: 10).
    robot_radius : float
        Radius (m) of the robot the episodes are for (erodes the free space).
    goal_radius : float or None
        Success distance (m) recorded with each goal; None leaves it to the task.
    max_goals_per_episode : int
        Goals tried for one episode before :class:`SamplingError`.
    """

    geodesic_range: tuple[float, float] = (1.0, 30.0)
    ratio_threshold: float = 1.1
    island_radius_limit: float = 1.5
    retries_per_goal: int = 10
    robot_radius: float = 0.18
    goal_radius: float | None = 0.5
    max_goals_per_episode: int = 1000

    def __post_init__(self) -> None:
        def number(name: str, value: Any, minimum: float) -> None:
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, float))
                or not math.isfinite(value)
                or value < minimum
            ):
                raise ArgumentError(f"{name} must be a finite number >= {minimum}, got {value!r}")

        lo_hi = self.geodesic_range
        if not isinstance(lo_hi, (tuple, list)) or len(lo_hi) != 2:
            raise ArgumentError(f"geodesic_range must be (min, max) in metres, got {lo_hi!r}")
        number("geodesic_range[0]", lo_hi[0], 0.0)
        number("geodesic_range[1]", lo_hi[1], 0.0)
        if not lo_hi[0] < lo_hi[1]:
            raise ArgumentError(f"geodesic_range must have min < max, got {lo_hi!r}")
        number("ratio_threshold", self.ratio_threshold, 1.0)
        number("island_radius_limit", self.island_radius_limit, 0.0)
        number("robot_radius", self.robot_radius, 0.0)
        if self.goal_radius is not None:
            validation.goal_tolerance("goal_radius", self.goal_radius)
        for name in ("retries_per_goal", "max_goals_per_episode"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ArgumentError(f"{name} must be an integer >= 1, got {value!r}")


def _pick_cell(tmap: Any, radius: float, rng: np.random.Generator) -> NDArray[np.float64]:
    cells = np.flatnonzero(tmap.usable(radius))
    return cell_centre(tmap, int(cells[int(rng.integers(len(cells)))]))


def generate_episodes(
    scene: Scene,
    scene_id: str,
    n_episodes: int,
    seed: int | np.random.SeedSequence | None = 0,
    config: GeneratorConfig | None = None,
    id_prefix: str = "",
    first_id: int = 0,
    stats: dict[str, Any] | None = None,
    pedestrians: Any = None,
) -> list[PointNavEpisode]:
    """Generate ``n_episodes`` episodes on ``scene`` with Habitat's rules (module notes).

    Parameters
    ----------
    scene : Scene
    scene_id : str
        Recorded in every episode.
    n_episodes : int
        How many episodes (>= 0).
    seed : int or SeedSequence or None
        Seeds the one random generator every draw comes from.
    config : GeneratorConfig, optional
        The rules' parameters (Habitat's defaults).
    id_prefix : str
        Episode ids are ``f"{id_prefix}{first_id + k}"``.
    first_id : int
    stats : dict, optional
        If given, filled with what happened: ``"rejected"`` (rule -> count over the whole
        run) and ``"ratio_trials"``, a list of ``(ratio, kept)`` for every pair that met
        the ratio filter (for measuring it).
    pedestrians : dict, optional
        Record a crowd of these settings in every episode (module notes).

    Returns
    -------
    list of PointNavEpisode

    Raises
    ------
    SamplingError
        When ``max_goals_per_episode`` goals in a row gave no acceptable pair (the message
        counts the rejections by rule), or an episode's crowd does not fit.
    """
    config = config or GeneratorConfig()
    if isinstance(n_episodes, bool) or not isinstance(n_episodes, int) or n_episodes < 0:
        raise ArgumentError(f"n_episodes must be an integer >= 0, got {n_episodes!r}")
    crowd_config = make_pedestrians(pedestrians)
    crowd = None if crowd_config is None else Crowd(crowd_config, scene)
    crowd_rng = np.random.default_rng(_crowd_seed(seed))
    rng = np.random.default_rng(seed)
    radius = config.robot_radius
    floor_p = _floor_weights(scene, scene_id, radius)
    episodes: list[PointNavEpisode] = []
    stats = {} if stats is None else stats
    total: dict[str, int] = stats.setdefault("rejected", {})
    trials: list[tuple[float, bool]] = stats.setdefault("ratio_trials", [])
    while len(episodes) < n_episodes:
        rejected = dict.fromkeys(_RULES, 0)
        pair = _draw_pair(scene, rng, config, floor_p, rejected, trials)
        for rule, count in rejected.items():
            total[rule] = total.get(rule, 0) + count
        if pair is None:
            detail = ", ".join(f"{k}: {v}" for k, v in rejected.items())
            raise SamplingError(
                f"could not generate episode {len(episodes)} on scene {scene_id!r}: no acceptable "
                f"start for {config.max_goals_per_episode} goals in a row ({detail})"
            )
        yaw = float(rng.uniform(0.0, 2.0 * math.pi))
        episode_id = f"{id_prefix}{first_id + len(episodes)}"
        episodes.append(_episode(scene, scene_id, episode_id, pair, yaw, config, crowd, crowd_rng))
    return episodes


def _episode(
    scene: Scene, scene_id: str, episode_id: str, pair: tuple[int, NDArray[np.float64], NDArray[np.float64], float],
    yaw: float, config: GeneratorConfig, crowd: Crowd | None, crowd_rng: np.random.Generator,
) -> PointNavEpisode:
    """The episode of a drawn ``(floor, goal, start, geodesic)`` ``pair`` (m) and heading
    ``yaw`` (rad), with a crowd drawn from ``crowd_rng`` when ``crowd`` is given."""
    floor, goal, start, geodesic = pair
    z = scene.floors[floor].height
    if crowd is not None:  # clear of the robot at its start, as the env's reset places it
        crowd.spawn(floor, crowd_rng, np.array([[start[0], start[1], config.robot_radius]]))
    return PointNavEpisode(
        episode_id=episode_id,
        scene_id=scene_id,
        floor=floor,
        start_position=(float(start[0]), float(start[1]), z),
        start_rotation=(0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw)),
        goal_position=(float(goal[0]), float(goal[1]), z),
        goal_radius=config.goal_radius,
        geodesic_distance=float(geodesic),
        robot_radius=config.robot_radius,
        pedestrians=None if crowd is None else crowd.record(),
    )


#: Appended to the seed's spawn key for the crowds' generator ("crowd" in ASCII).
_CROWD_KEY = 0x63726F7764


def _crowd_seed(seed: int | np.random.SeedSequence | None) -> np.random.SeedSequence:
    """The seed of the crowds' generator: the episodes' ``seed`` with its own spawn key."""
    if isinstance(seed, np.random.SeedSequence):
        return np.random.SeedSequence(seed.entropy, spawn_key=(*seed.spawn_key, _CROWD_KEY))
    return np.random.SeedSequence(seed, spawn_key=(_CROWD_KEY,))


def _floor_weights(scene: Scene, scene_id: str, radius: float) -> NDArray[np.float64]:
    """Each floor's probability of holding an episode: its share of usable cells for a robot
    of ``radius`` m."""
    areas = np.array([f.usable(radius).sum() for f in scene.floors], dtype=np.float64)
    if not areas.sum():
        raise SamplingError(
            f"scene {scene_id!r} has no usable cell for a robot of radius {radius} m"
        )
    return areas / areas.sum()


# The rejection rules, in the order the counts are reported.
_RULES = (
    "goal on a small island",
    "no path",
    "geodesic out of range",
    "ratio filter",
    "start on a small island",
)


def _draw_pair(
    scene: Scene,
    rng: np.random.Generator,
    config: GeneratorConfig,
    floor_p: NDArray[np.float64],
    rejected: dict[str, int],
    trials: list[tuple[float, bool]],
) -> tuple[int, NDArray[np.float64], NDArray[np.float64], float] | None:
    """Draw goals until one has an acceptable start: ``(floor, goal, start, geodesic)``
    (positions in m), or None after ``max_goals_per_episode`` goals. Rejections are counted
    in ``rejected`` by rule."""
    radius = config.robot_radius
    for _ in range(config.max_goals_per_episode):
        floor = int(rng.choice(len(floor_p), p=floor_p))
        goal = _pick_cell(scene.floors[floor], radius, rng)
        if island_radius(scene, floor, goal, radius) < config.island_radius_limit:
            rejected["goal on a small island"] += 1
            continue
        found = _draw_start(scene, floor, goal, rng, config, rejected, trials)
        if found is not None:
            return floor, goal, found[0], found[1]
    return None


def _draw_start(
    scene: Scene,
    floor: int,
    goal: NDArray[np.float64],
    rng: np.random.Generator,
    config: GeneratorConfig,
    rejected: dict[str, int],
    trials: list[tuple[float, bool]],
) -> tuple[NDArray[np.float64], float] | None:
    """Draw starts for ``goal`` until one passes every rule: ``(start, geodesic)`` (m), or
    None after ``retries_per_goal`` tries."""
    radius = config.robot_radius
    near, far = config.geodesic_range
    tmap = scene.floors[floor]
    for _ in range(config.retries_per_goal):
        start = _pick_cell(tmap, radius, rng)
        euclid = math.hypot(*(goal - start))
        if euclid > far:  # the geodesic is at least as long
            rejected["geodesic out of range"] += 1
            continue
        geodesic = scene.geodesic_distance(floor, start, goal, robot=radius)
        if geodesic == math.inf:
            rejected["no path"] += 1
            continue
        if not near <= geodesic <= far:
            rejected["geodesic out of range"] += 1
            continue
        ratio = geodesic / euclid
        if ratio < config.ratio_threshold:
            kept = not rng.random() > ratio_keep_probability(ratio)
            trials.append((ratio, kept))
            if not kept:
                rejected["ratio filter"] += 1
                continue
        if island_radius(scene, floor, start, radius) < config.island_radius_limit:
            rejected["start on a small island"] += 1
            continue
        return start, geodesic
    return None


def scene_seed(seed: int, scene_id: str) -> np.random.SeedSequence:
    """The seed of one scene's episodes: from the run's ``seed`` and the scene's id only, so
    a scene's episodes do not depend on which other scenes are generated."""
    digest = hashlib.sha256(scene_id.encode("utf-8")).digest()
    return np.random.SeedSequence([int(seed), int.from_bytes(digest[:8], "little")])


def generate_split(
    scene_set: SceneSet,
    split: str,
    n_episodes: int,
    seed: int = 0,
    config: GeneratorConfig | None = None,
    root: str | None = None,
    progress: Callable[[int], None] | None = None,
    pedestrians: Any = None,
) -> EpisodeDataset:
    """Generate ``n_episodes`` episodes spread evenly over the scenes of one split.

    Scene ``k`` of the split gets ``n_episodes // n_scenes`` episodes, one more for the
    first ``n_episodes % n_scenes`` scenes; episode ids are ``"0"``, ``"1"``, ... in that
    order. Each scene's episodes are seeded by :func:`scene_seed`.

    Parameters
    ----------
    scene_set : SceneSet
    split : str
    n_episodes : int
    seed : int
    config : GeneratorConfig, optional
    root : str, optional
        Folder relative scene paths are read from.
    progress : callable, optional
        Called with the number of episodes generated for each scene.
    pedestrians : dict, optional
        Record a crowd of these settings in every episode (:func:`generate_episodes`); the
        dict is kept in the metadata.
    """
    config = config or GeneratorConfig()
    make_pedestrians(pedestrians)  # refused before any scene is built
    ids = scene_set.scene_ids(split)
    if not ids:
        raise ArgumentError(f"split {split!r} of scene set {scene_set.name!r} has no scenes")
    if isinstance(n_episodes, bool) or not isinstance(n_episodes, int) or n_episodes < 1:
        raise ArgumentError(f"n_episodes must be an integer >= 1, got {n_episodes!r}")
    episodes: list[PointNavEpisode] = []
    for k, scene_id in enumerate(ids):
        count = n_episodes // len(ids) + (k < n_episodes % len(ids))
        if not count:
            continue
        scene = load_scene(scene_id, root)
        episodes += generate_episodes(
            scene,
            scene_id,
            count,
            seed=scene_seed(seed, scene_id),
            config=config,
            first_id=len(episodes),
            pedestrians=pedestrians,
        )
        if progress is not None:
            progress(count)
    metadata = {
        "scene_set": scene_set.name,
        "split": split,
        "seed": int(seed),
        "generator": {**asdict(config), "geodesic_range": list(config.geodesic_range)},
    }
    if isinstance(pedestrians, Mapping):
        metadata["pedestrians"] = dict(pedestrians)
    return EpisodeDataset(episodes, metadata)
