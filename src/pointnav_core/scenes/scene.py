"""Scenes: one or more floors, with sampling and geodesic shortest paths.

A :class:`Scene` is a list of floors (:class:`~pointnav_core.floor.maps.TraversableMap`, each
with its own height) and the API of OmniGibson's ``TraversableScene``, so that ported code
reads the same:

=============================================  ==========================================
member                                         meaning
=============================================  ==========================================
``n_floors``, ``get_floor_height(floor)``      floors and their z (m)
``get_random_point(floor, reference_point,     uniform usable point (a cell centre), in
robot, rng) -> (floor, xyz)``                  the reference point's component if given
``get_shortest_path(floor, source_xy,          any-angle path (N, 2) from the true source
target_xy, entire_path, robot)``               to the true target and its length (m)
``geodesic_distance(floor, source, target)``   the length alone
``goal_field(floor, goal_xy, robot)``          cached per-goal distance field (hot path)
=============================================  ==========================================

Unreachable is ``math.inf`` everywhere (``get_shortest_path``: ``(None, inf)``), proven by two
label lookups when the points lie in different :mod:`~pointnav_core.floor.reachability` components.

``robot`` is anything with a ``radius`` attribute (a ``RobotSpec``), a radius in metres, or
None for a point robot. Scenes are built from arrays, shapely polygons, OmniGibson
traversability PNGs, MovingAI maps, ROS maps, ProcTHOR or HouseExpo plans, or generated.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from os import PathLike
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pointnav_core import floorplans
from pointnav_core.errors import ArgumentError, SamplingError
from pointnav_core.floor import loaders, reachability
from pointnav_core.floor.draw import cell_centre, draw_point
from pointnav_core.floor.maps import OBSTACLE, TraversableMap
from pointnav_core.floorplans import FloorPlan
from pointnav_core.geodesic import Planner, planner_for
from pointnav_core.geodesic.paths import resample_path
from pointnav_core.scenes.goal_field import FloorGoalField, as_xy
from pointnav_core.utils import validation

__all__ = ["Scene", "robot_radius"]


def robot_radius(robot: Any) -> float:
    """Radius in metres of a robot spec (``.radius``), a number, or None (a point: 0.0)."""
    if robot is None:
        return 0.0
    radius = getattr(robot, "radius", robot)
    if not validation.is_real(radius):
        raise ArgumentError(
            f"robot must be a robot spec with a radius, a radius in metres, or None; got {robot!r}"
        )
    return validation.real("robot radius", radius, minimum=0.0)


def _as_rng(rng: np.random.Generator | int | None) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    return np.random.default_rng(rng)


class Scene:
    """A navigable scene: floors with heights, sampling and geodesic paths.

    Parameters
    ----------
    floors : sequence of TraversableMap
        One map per floor, floor 0 first; each map carries its floor height.
    num_waypoints : int
        Waypoints returned by :meth:`get_shortest_path` when ``entire_path=False``.
    waypoint_spacing : float
        Spacing (m) of those waypoints along the path.
    floor_plans : sequence of FloorPlan or None, optional
        Accepted for compatibility: a floor's plan is its map's ``geometry`` (give it to
        :class:`TraversableMap`), so an entry must be None or that same plan.
    scene_id : str, optional
        The name datasets give this scene (``rooms:0``, a path), set by
        :func:`pointnav_core.datasets.load_scene` and the generators (``rooms`` ...). Every
        env refuses a dataset episode of another ``scene_id``; None checks nothing.

    Examples
    --------
    >>> scene = Scene.from_array(np.ones((40, 40), bool), resolution=0.1)
    >>> scene.n_floors, scene.get_floor_height(0)
    (1, 0.0)
    >>> path, dist = scene.get_shortest_path(0, (0.5, 0.5), (3.5, 0.5), entire_path=True)
    >>> round(dist, 6), path.shape
    (3.0, (2, 2))
    """

    def __init__(
        self,
        floors: Sequence[TraversableMap],
        *,
        num_waypoints: int = 10,
        waypoint_spacing: float = 0.2,
        floor_plans: Sequence[FloorPlan | None] | None = None,
        scene_id: str | None = None,
    ) -> None:
        floors = list(floors)
        if not floors or not all(isinstance(f, TraversableMap) for f in floors):
            raise ArgumentError("floors must be a non-empty sequence of TraversableMap")
        if int(num_waypoints) != num_waypoints or num_waypoints < 1:
            raise ArgumentError(f"num_waypoints must be an integer >= 1, got {num_waypoints!r}")
        if not math.isfinite(waypoint_spacing) or waypoint_spacing <= 0:
            raise ArgumentError(f"waypoint_spacing must be > 0 (m), got {waypoint_spacing!r}")
        if floor_plans is not None:
            plans = list(floor_plans)
            if len(plans) != len(floors):
                raise ArgumentError(
                    f"floor_plans must have one entry per floor ({len(floors)}), got {len(plans)}"
                )
            for i, (plan, tmap) in enumerate(zip(plans, floors)):
                if plan is not None and plan is not tmap.geometry:
                    raise ArgumentError(
                        f"floor_plans[{i}] is not floor {i}'s geometry: a floor's plan lives on "
                        f"its map, TraversableMap(..., geometry=plan)"
                    )
        if scene_id is not None and (not isinstance(scene_id, str) or not scene_id):
            raise ArgumentError(f"scene_id must be None or a non-empty string, got {scene_id!r}")
        self.scene_id = scene_id
        self.floors = floors
        self.num_waypoints = int(num_waypoints)
        self.waypoint_spacing = float(waypoint_spacing)

    @property
    def floor_plans(self) -> tuple[FloorPlan | None, ...]:
        """Each floor's plan (the polygons it was rasterised from) or None: its map's
        ``geometry``, stored there once."""
        return tuple(f.geometry for f in self.floors)

    # ------------------------------------------------------------- constructors
    @classmethod
    def from_array(
        cls,
        grid: ArrayLike | Sequence[ArrayLike],
        resolution: float,
        origin: tuple[float, float] = (0.0, 0.0),
        heights: Sequence[float] | None = None,
        **kwargs: Any,
    ) -> Scene:
        """Scene from one 2D array per floor: booleans (True = free) or cell codes.

        Parameters
        ----------
        grid : array_like (H, W), (F, H, W), or a sequence of 2D arrays
            The floors' grids.
        resolution : float
            Metres per cell.
        origin : (float, float)
            World (x, y) of the outer corner of cell (0, 0), shared by all floors.
        heights : sequence of float, optional
            Floor heights (m); default ``0, 3, 6, ...``.
        """
        if isinstance(grid, np.ndarray) and grid.ndim == 2:
            grids = [grid]
        elif isinstance(grid, np.ndarray) and grid.ndim == 3:
            grids = list(grid)
        elif isinstance(grid, (list, tuple)) and grid and np.ndim(grid[0]) == 2:
            grids = list(grid)
        else:
            grids = [np.asarray(grid)]
        heights = cls._heights(heights, len(grids))
        floors = [TraversableMap(g, resolution, origin, h) for g, h in zip(grids, heights)]
        return cls(floors, **kwargs)

    @classmethod
    def from_polygons(
        cls,
        floor: Any,
        obstacles: Sequence[Any] = (),
        resolution: float = 0.05,
        height: float = 0.0,
        **kwargs: Any,
    ) -> Scene:
        """Scene of one floor from a shapely outline (outside = VOID) and obstacle polygons.

        Cells are classified by their centres with shapely's vectorised predicates. The
        obstacle polygons also join the floor's blocked set (see
        :attr:`TraversableMap.collision`), so an obstacle thinner than a cell still blocks.
        """
        plan = FloorPlan(outline=floor, obstacles=tuple(obstacles))
        codes, origin = floorplans.rasterize(plan.outline, plan.obstacles, resolution)
        tmap = TraversableMap(codes, resolution, origin, height, geometry=plan)
        return cls([tmap], **kwargs)

    @classmethod
    def from_png(
        cls,
        paths: str | PathLike[str] | Sequence[str | PathLike[str]],
        resolution: float = 0.1,
        source_resolution: float = 0.01,
        heights: Sequence[float] | None = None,
        **kwargs: Any,
    ) -> Scene:
        """Scene from OmniGibson ``floor_trav_<n>.png`` images, one per floor (see loaders)."""
        if isinstance(paths, (str, PathLike)):
            paths = [paths]
        paths = list(paths)
        heights = cls._heights(heights, len(paths))
        floors = []
        for path, h in zip(paths, heights):
            codes, origin = loaders.read_trav_png(path, resolution, source_resolution)
            floors.append(TraversableMap(codes, resolution, origin, h))
        return cls(floors, **kwargs)

    @classmethod
    def from_movingai(
        cls, path: str | PathLike[str], resolution: float = 0.5, **kwargs: Any
    ) -> Scene:
        """Scene from a MovingAI ``.map`` grid benchmark file.

        ``resolution`` is metres per map character; the default 0.5 m makes a corridor one
        character wide passable for the default robot (radius 0.18 m). Out of bounds in a
        game map is a wall, not a drop: the map is framed by one ring of OBSTACLE cells, and
        the origin moves out by one cell so that character ``(row, col)`` still covers
        ``[col, col + 1) x [row, row + 1)`` times ``resolution``.
        """
        res = validation.real("resolution", resolution, minimum=0.0, strict=True, unit="m per character")
        codes = np.pad(loaders.read_movingai(path), 1, constant_values=OBSTACLE)
        return cls([TraversableMap(codes, res, origin=(-res, -res))], **kwargs)

    @classmethod
    def from_ros_map(cls, yaml_path: str | PathLike[str], *, unknown: str = "void", lethal_threshold: int = 100,
                     ignore_yaw: bool = False, height: float = 0.0, **kwargs: Any) -> Scene:
        """Scene of one floor from a ROS map_server ``map.yaml`` and its PGM / PNG image, read by
        map_server's rules (see :func:`pointnav_core.floor.ros_maps.ros_map_floor`)."""
        from pointnav_core.floor.ros_maps import ros_map_floor

        return cls([ros_map_floor(yaml_path, unknown=unknown, lethal_threshold=lethal_threshold,
                                  ignore_yaw=ignore_yaw, height=height)], **kwargs)

    @classmethod
    def from_procthor(cls, house_json: str | PathLike[str], resolution: float = 0.05, wall_thickness: float = 0.1,
                      object_sizes: Any = None, doors: str = "open", **kwargs: Any) -> Scene:
        """Scene of a ProcTHOR ``house.json``: rooms as floor, walls with door holes as obstacles,
        exact polygons (see :func:`pointnav_core.floorplans.files.read_procthor`). ``doors``:
        ``"open"`` (every door a hole), ``"as_stored"`` (closed where ``openness`` is 0) or
        ``"closed"`` (no holes)."""
        from pointnav_core.floorplans.files import read_procthor

        plan = read_procthor(house_json, wall_thickness=wall_thickness, object_sizes=object_sizes, doors=doors)
        return cls.from_polygons(plan.outline, plan.obstacles, resolution=resolution, **kwargs)

    @classmethod
    def from_houseexpo(cls, path: str | PathLike[str], resolution: float = 0.05, **kwargs: Any) -> Scene:
        """Scene of a HouseExpo ``<id>.json``: its ``verts`` (m) as the exact floor outline."""
        from pointnav_core.floorplans.files import read_houseexpo

        plan = read_houseexpo(path)
        return cls.from_polygons(plan.outline, plan.obstacles, resolution=resolution, **kwargs)

    def to_ros_map(self, yaml_path: str | PathLike[str], floor: int = 0) -> str:
        """Write ``floor``'s grid as a trinary map_server map (yaml + PGM); returns the image path."""
        from pointnav_core.floor import ros_maps

        return ros_maps.write_ros_map(self._floor(floor), yaml_path)

    @staticmethod
    def _heights(heights: Sequence[float] | None, n: int) -> list[float]:
        if heights is None:
            return [3.0 * i for i in range(n)]
        heights = [float(h) for h in heights]
        if len(heights) != n:
            raise ArgumentError(f"heights must have one value per floor ({n}), got {len(heights)}")
        return heights

    # ------------------------------------------------------------------ floors
    @property
    def n_floors(self) -> int:
        """Number of floors."""
        return len(self.floors)

    def _floor(self, floor: int) -> TraversableMap:
        if isinstance(floor, bool) or not isinstance(floor, (int, np.integer)):
            raise ArgumentError(f"floor must be an integer in [0, {self.n_floors}), got {floor!r}")
        if not 0 <= floor < self.n_floors:
            raise ArgumentError(f"floor must be in [0, {self.n_floors}), got {floor}")
        return self.floors[int(floor)]

    def get_floor_height(self, floor: int = 0) -> float:
        """Height (world z, m) of ``floor``."""
        return self._floor(floor).height

    def planner(self, floor: int, robot: Any = None) -> Planner:
        """The cached tangent-graph planner of ``floor`` for ``robot``'s radius."""
        return planner_for(self._floor(floor), robot_radius(robot))

    def is_usable(self, floor: int, xy: ArrayLike, robot: Any = None) -> bool:
        """Whether the robot's centre can stand at world point ``xy`` on ``floor``."""
        return bool(self._floor(floor).is_usable(as_xy(xy, "xy"), robot_radius(robot)))

    # ---------------------------------------------------------------- sampling
    def get_random_point(
        self,
        floor: int | None = None,
        reference_point: ArrayLike | None = None,
        robot: Any = None,
        rng: np.random.Generator | int | None = None,
        max_distance: float | None = None,
    ) -> tuple[int, NDArray[np.float64]]:
        """Sample a usable point uniformly over the robot-eroded free space.

        Parameters
        ----------
        floor : int, optional
            Floor to sample on; None picks one of the floors with usable space at random.
        reference_point : array_like, optional
            (x, y[, z]); the point is then drawn from the component that contains it. A
            reference point that is not usable raises ``ValueError``.
        robot : RobotSpec, float or None
            Whose radius erodes the free space.
        rng : numpy Generator, int seed, or None
        max_distance : float, optional
            With ``reference_point``: draw only among points at most this far (m, xy) from
            it. A geodesic is never shorter, so a sampler that wants geodesics below a
            bound loses no candidate and rejects far fewer.

        Returns
        -------
        floor : int
        point : ndarray, shape (3,)
            A usable cell centre ``(x, y, z)`` with z the floor height (m).

        Raises
        ------
        SamplingError
            When the floor (or the component) has no usable cell for this radius.
        """
        rng = _as_rng(rng)
        radius = robot_radius(robot)
        if max_distance is not None:
            if reference_point is None:
                raise ArgumentError("max_distance needs a reference_point to measure from")
            if not (validation.is_real(max_distance) and max_distance >= 0):
                raise ArgumentError(f"max_distance must be None or a number >= 0 (m), got {max_distance!r}")
        if floor is None:
            candidates = [i for i, f in enumerate(self.floors) if len(f.usable_indices(radius))]
            if not candidates:
                raise SamplingError(f"no floor has a usable cell for a robot of radius {radius} m")
            floor = candidates[int(rng.integers(len(candidates)))]
        tmap = self._floor(floor)
        # Usable cell centres: the disc misses the floor's one blocked set, which every
        # backend collides with, so every backend accepts the point.
        if reference_point is None:
            cells = tmap.usable_indices(radius)
            index = int(cells[int(rng.integers(len(cells)))]) if len(cells) else None
            point = None if index is None else cell_centre(tmap, index)
        else:
            ref = as_xy(reference_point, "reference_point")
            label = int(tmap.component_at(ref, radius))
            if label == 0:
                raise ArgumentError(
                    f"reference_point {ref.tolist()} is not usable on floor {floor} for a robot "
                    f"of radius {radius} m (blocked, too close to an obstacle, or off the map)"
                )
            point = draw_point(tmap, radius, label, ref, max_distance, rng)
        if point is None:
            within = "" if max_distance is None else f" within {max_distance} m of the reference point"
            raise SamplingError(
                f"floor {floor} has no usable cell{within} for a robot of radius {radius} m"
            )
        x, y = point
        return int(floor), np.array([x, y, tmap.height])

    # ---------------------------------------------------------------- geodesic
    def goal_field(self, floor: int, goal_xy: ArrayLike, robot: Any = None) -> FloorGoalField:
        """Cached geodesic distance field to ``goal_xy`` on ``floor`` (see FloorGoalField)."""
        planner = planner_for(self._floor(floor), robot_radius(robot))
        return FloorGoalField(self._floor(floor), planner.goal_field(as_xy(goal_xy, "goal_xy")))

    def geodesic_distance(
        self, floor: int, source_xy: ArrayLike, target_xy: ArrayLike, robot: Any = None
    ) -> float:
        """Geodesic distance (m) between two points; ``math.inf`` when there is no path.

        Exact for the given points. Uses the target's goal field when it is cached, and one
        A* search otherwise (no field is built). Use :meth:`goal_field` for repeated queries.
        """
        return self._shortest(floor, source_xy, target_xy, robot)[1]

    def _shortest(
        self, floor: int, source_xy: ArrayLike, target_xy: ArrayLike, robot: Any
    ) -> tuple[NDArray[np.float64] | None, float]:
        tmap, radius = self._floor(floor), robot_radius(robot)
        src, tgt = as_xy(source_xy, "source_xy"), as_xy(target_xy, "target_xy")
        if reachability.disconnected(tmap, radius, src, tgt):  # proven in O(1), no search
            return None, math.inf
        planner = planner_for(tmap, radius)
        if planner.has_field(tgt):
            points, length = planner.goal_field(tgt).path(src)
        else:
            points, length = planner.shortest_path(src, tgt)
        if points is None:
            return None, math.inf
        return points, float(length)

    def get_shortest_path(
        self,
        floor: int,
        source_xy: ArrayLike,
        target_xy: ArrayLike,
        entire_path: bool = False,
        robot: Any = None,
    ) -> tuple[NDArray[np.float64] | None, float]:
        """Shortest collision-free path of the robot's centre and its geodesic length.

        Parameters
        ----------
        floor : int
        source_xy, target_xy : array_like
            (x, y) or (x, y, z) in metres; z is ignored.
        entire_path : bool
            True: the whole path, source, tangent points, arcs drawn as short pieces that
            keep the full radius, target. False: the first ``num_waypoints`` points spaced
            ``waypoint_spacing`` apart along it, padded with the target (OmniGibson's
            convention).
        robot : RobotSpec, float or None

        Returns
        -------
        waypoints : ndarray (N, 2) or None
        geodesic_distance : float
            Exact length in metres of the shortest path of the disc's centre. ``(None,
            math.inf)`` when the target is unreachable from the source, or the robot does not
            fit at either (the same ``inf`` as :meth:`geodesic_distance` and goal fields).
        """
        points, length = self._shortest(floor, source_xy, target_xy, robot)
        if points is None:
            return None, math.inf
        if not entire_path:
            points = resample_path(points, self.waypoint_spacing, self.num_waypoints)
        return points, length

    def __repr__(self) -> str:
        return f"Scene(n_floors={self.n_floors}, floors={self.floors!r})"
