"""Values that used to be coerced silently are refused, naming the parameter (issue 10).

A bool is not a number, a string is not a number or a range of numbers, a complex or
string action is not an action, and a control rate must give a sensible step.
"""

from __future__ import annotations

import numpy as np
import pytest

from pointnav_core import scenes
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import FREE, OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.task import PointNavigationTask
from pointnav_core.utils.validation import boolean, integer, is_real, real, vector


def small_scene() -> Scene:
    grid = np.full((30, 40), FREE, dtype=np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = OBSTACLE
    return Scene.from_array(grid, 0.1)


CASES = [
    # (what is built, the parameter named first in the message)
    (lambda: RobotSpec(radius=True), "radius"),
    (lambda: RobotSpec(radius="0.2"), "radius"),
    (lambda: RobotSpec(max_linear_velocity=np.True_), "max_linear_velocity"),
    (lambda: RobotSpec(max_angular_velocity=1 + 0j), "max_angular_velocity"),
    (lambda: PointNavigationTask(goal_tolerance=True), "goal_tolerance"),
    (lambda: PointNavigationTask(goal_tolerance="0.5"), "goal_tolerance"),
    (lambda: PointNavigationTask(path_range="12"), "path_range"),
    (lambda: PointNavigationTask(path_range=(True, 3.0)), "path_range"),
    (lambda: PointNavigationTask(initial_pos=(True, 1.0, 0.0)), "initial_pos"),
    (lambda: PointNavigationTask(goal_pos=["1", "2", "0"]), "goal_pos"),
    (lambda: PointNavigationTask(goal_pos="123"), "goal_pos"),
    (lambda: PointNavigationTask(initial_quat=["0", "0", "0", "1"]), "initial_quat"),
    (lambda: PointNavigationTask(robot_idn=np.True_), "robot_idn"),
    (lambda: PointNavigationTask(floor=1.0), "floor"),
    (
        lambda: PointNavigationTask(termination_config={"fall_height": "0.1"}),
        "termination_config: fall_height",
    ),
    (
        lambda: PointNavigationTask(termination_config={"max_steps": 2.0}),
        "termination_config: max_steps",
    ),
    (lambda: PointNavigationTask(reward_config={"r_collision": "1"}), "reward_config: r_collision"),
    (lambda: PointNavEnv(action_frequency=1e-9), "action_frequency"),
    (lambda: PointNavEnv(action_frequency="10"), "action_frequency"),
    (lambda: PointNavEnv(action_frequency=np.inf), "action_frequency"),
    (lambda: MultiPointNavEnv(action_frequency=True), "action_frequency"),
    (lambda: scenes.rooms(seed=True), "seed"),
    (lambda: scenes.rooms(seed=0, size=("20", "15")), "size"),
    (lambda: Scene.from_array(np.zeros((5, 5), np.uint8), True), "resolution"),
    (lambda: Scene.from_array(np.zeros((5, 5), np.uint8), "0.1"), "resolution"),
    (lambda: Scene.from_array(np.zeros((5, 5), np.uint8), 0.1, origin=("0", "0")), "origin"),
    (lambda: small_scene().get_random_point(0, robot=True), "robot"),
    (lambda: small_scene().is_usable(0, "12"), "xy"),
]


@pytest.mark.parametrize(("build", "name"), CASES, ids=[name for _, name in CASES])
def test_a_coerced_value_is_refused_naming_its_parameter(build, name):
    with pytest.raises(ValueError) as excinfo:
        build()
    assert str(excinfo.value).startswith(name), str(excinfo.value)


@pytest.mark.parametrize(
    "action",
    [
        np.array([1 + 1j, 0.0]),
        np.array(["1", "0"]),
        ["1", "0"],
        np.array([True, False]),
        [True, 0.0],
        "10",
        None,
    ],
    ids=["complex", "string array", "string list", "bool array", "bool item", "string", "None"],
)
def test_actions_that_are_not_real_numbers_are_refused(action):
    env = PointNavEnv(scene=small_scene())
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^action must be an array of 2 real numbers"):
        env.step(action)
    assert env.task.episode_length == 0  # nothing moved
    penv = MultiPointNavEnv(scene=small_scene(), n_robots=2)
    penv.reset(seed=0)
    expected = (
        "^missing action for robot_0"
        if action is None
        else "^robot_0: action must be an array of 2 real"
    )
    with pytest.raises(ValueError, match=expected):
        penv.step({"robot_0": action, "robot_1": np.zeros(2, np.float32)})


def test_real_numbers_of_every_kind_are_still_accepted():
    assert RobotSpec(radius=np.float32(0.25)).radius == 0.25
    assert RobotSpec(max_linear_velocity=1).max_linear_velocity == 1.0
    assert PointNavigationTask(goal_pos=np.array([1, 2, 0])).goal_pos is not None
    assert PointNavigationTask(path_range=(0, np.inf)).path_range == (0.0, np.inf)
    assert PointNavEnv(scene=small_scene(), action_frequency=np.int64(20)).action_frequency == 20.0
    env = PointNavEnv(scene=small_scene())
    env.reset(seed=0)
    env.step([1, 0])  # a list of ints is an action
    env.step(np.array([0.5, 0.0], dtype=np.float32))


def test_the_helpers_follow_the_rules_by_hand():
    assert [
        is_real(v) for v in (1, 1.5, np.int8(2), np.float32(1), True, np.bool_(1), "1", 1j, None)
    ] == [
        True,
        True,
        True,
        True,
        False,
        False,
        False,
        False,
        False,
    ]
    assert real("x", 2, minimum=0.0, strict=True) == 2.0
    with pytest.raises(ValueError, match=r"^x must be a finite number > 0 \(m\), got 0"):
        real("x", 0, minimum=0.0, strict=True)
    with pytest.raises(
        ValueError, match=r"^p must be a finite number >= 0 and <= 1 \(a probability\)"
    ):
        real("p", 1.5, minimum=0.0, maximum=1.0, unit="a probability")
    assert real("x", np.inf, finite=False) == np.inf
    with pytest.raises(ValueError, match="x must be a number"):
        real("x", np.nan, finite=False)
    assert integer("n", np.int16(3), minimum=0) == 3
    for bad in (3.0, True, "3", -1):
        with pytest.raises(ValueError, match=r"^n must be an integer >= 0"):
            integer("n", bad, minimum=0)
    assert boolean("b", np.bool_(True)) is True
    with pytest.raises(ValueError, match="^b must be True or False"):
        boolean("b", 1)
    assert vector("v", (1, 2.5), sizes=(2,)).tolist() == [1.0, 2.5]
    for bad in (
        "12",
        (1, "2"),
        (1, True),
        np.array([1j, 2]),
        np.array([[1, 2]]),
        (1, 2, 3),
        (1, np.nan),
    ):
        with pytest.raises(ValueError, match=r"^v must be 2 finite numbers"):
            vector("v", bad, sizes=(2,))
