"""Episode sampling: every constraint holds, a hook adds one, failure is bounded and named."""

import math

import numpy as np
import pytest

from pointnav_core.envs import multi_pointnav as parallel
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.errors import SamplingError
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task.sampling import sample_episode


def room(cells: int = 40) -> Scene:
    grid = np.full((cells, cells), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


def sample(env, **kw):
    task = env.task
    args = dict(
        robot_idn=0, floor=0, spec=env.robots[0], floor_height=0.0, initial_pos=None, initial_quat=None,
        goal_pos=None, goal_tolerance=task.goal_tolerance, path_range=None, max_trials=task.max_trials,
    )
    return sample_episode(env, **{**args, **kw})


def test_a_goal_constraint_decides_which_goals_are_kept():
    env = PointNavEnv(scene=room())
    env.reset(seed=0)
    for _ in range(20):
        episode = sample(env, goal_constraint=lambda gx, gy: None if gx > 2.0 else "the goal must be right of x = 2 m")
        gx, _ = episode.goal_xy
        assert gx > 2.0
        sx, sy = episode.start_xy
        assert math.dist(episode.start_xy, episode.goal_xy) >= env.task.goal_tolerance
        # The robot stands at the start it was landed at.
        assert env.backend.get_pose(0)[0][:2].tolist() == pytest.approx([sx, sy])
        # The geodesic in an empty room is the straight line.
        assert episode.geodesic == pytest.approx(math.dist(episode.start_xy, episode.goal_xy), rel=1e-9)


def test_failing_constraints_are_counted_and_the_worst_is_named():
    env = PointNavEnv(scene=room())
    env.reset(seed=0)
    calls = []

    def never(gx, gy):
        calls.append((gx, gy))
        return "the goal must be on the moon"

    with pytest.raises(SamplingError, match=r"in 7 trials: the goal must be on the moon \(.*failed \d+ time"):
        sample(env, goal_constraint=never, max_trials=7)
    assert 0 < len(calls) <= 7


def test_a_fixed_goal_is_not_subject_to_the_constraint():
    env = PointNavEnv(scene=room())
    env.reset(seed=0)
    episode = sample(env, goal_pos=(2.0, 2.0), goal_constraint=lambda gx, gy: "never")
    assert episode.goal_xy == (2.0, 2.0)


def test_a_multi_robot_reset_that_cannot_separate_goals_tries_max_trials_pairs_at_most():
    grid = np.full((28, 28), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    env = parallel.parallel_env(scene=Scene.from_array(grid, 0.1), n_robots=5, task={"goal_tolerance": 0.8})
    scene = env.unwrapped.scene if hasattr(env, "unwrapped") else env.scene
    drawn = []
    original = scene.get_random_point

    def counting(*args, **kw):
        drawn.append(1)
        return original(*args, **kw)

    scene.get_random_point = counting
    with pytest.raises(SamplingError, match="distinct from the other robots' goals"):
        env.reset(seed=0)
    # Two draws (start, goal) per trial; robots before the failing one took one trial or more.
    n_trials = env.tasks[0].max_trials
    assert len(drawn) <= 5 * 2 * n_trials


@pytest.mark.parametrize("resolution", [0.1, 0.05, 0.3])
@pytest.mark.parametrize("walls", [False, True])
def test_points_within_max_distance_are_exactly_those_math_hypot_keeps(resolution, walls):
    # Cell centres at exact distances (3-4-5 triangles on the grid) sit on the bound: the
    # draw must be among exactly the cells that math.hypot keeps, listed row-major, and
    # pick the one a list of them would (the same random number).
    grid = np.zeros((41, 41), np.uint8)
    if walls:  # rows split into several runs of the component
        grid[::4, 3::5] = 1
        grid[10, 5:35] = 1
    scene = Scene.from_array(grid, resolution=resolution)
    tmap = scene.floors[0]
    from pointnav_core.floor import draw_cell

    for ref in (tmap.cell_to_world(np.array([20, 20])), tmap.cell_to_world(np.array([20, 21])) + 0.3 * resolution):
        label = int(tmap.component_at(ref, 0.0))
        flat, xy = tmap.component_cells(0.0, label)
        for cells in (0.2, 5, 10, 12.5, 15, 60):
            bound = cells * resolution
            want = [i for i, (x, y) in zip(flat.tolist(), xy.tolist()) if math.hypot(x - ref[0], y - ref[1]) <= bound]
            for seed in range(20):
                got = draw_cell(tmap, 0.0, label, ref, bound, np.random.default_rng(seed))
                assert got == (want[int(np.random.default_rng(seed).integers(len(want)))] if want else None)
