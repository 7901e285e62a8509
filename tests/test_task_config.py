"""TaskConfig: the task's frozen, keyword-only, checked configuration, and the task's use of it."""

from __future__ import annotations

import dataclasses
import math
import pickle

import numpy as np
import pytest

from pointnav_core.task import PointNavigationTask, TaskConfig
from pointnav_core.task.config import compose_terms, merge_config
from pointnav_core.task.terminations import Timeout


def test_a_config_is_frozen_and_keyword_only():
    config = TaskConfig(goal_tolerance=0.3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.goal_tolerance = 1.0  # type: ignore[misc]
    with pytest.raises(TypeError):
        TaskConfig(0, 0)  # type: ignore[misc]
    assert config.goal_tolerance == 0.3


def test_positions_and_the_quaternion_are_normalised():
    # A quaternion of norm 1.0005 (within the 1e-3 tolerance) comes back unit length:
    # (0, 0, 0.6, 0.8) * 1.0005 / 1.0005.
    config = TaskConfig(
        initial_pos=np.array([1, 2, 7]), goal_pos=[3.5, 4], initial_quat=[0, 0, 0.6003, 0.8004]
    )
    assert config.initial_pos == (1.0, 2.0) and type(config.initial_pos[0]) is float
    assert config.goal_pos == (3.5, 4.0)
    x, y, z, w = config.initial_quat
    assert (x, y) == (0.0, 0.0)
    assert z == pytest.approx(0.6, abs=1e-12) and w == pytest.approx(0.8, abs=1e-12)
    assert math.isclose(z * z + w * w, 1.0, abs_tol=1e-12)


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("robot_idn", True, "^robot_idn must be an integer >= 0"),
        ("floor", -1, "^floor must be an integer >= 0"),
        ("initial_pos", "12", "^initial_pos must be None or a finite position"),
        ("initial_quat", [0, 0, 0, 2], "^initial_quat must be a unit quaternion"),
        ("goal_tolerance", True, "^goal_tolerance must be a finite number > 0"),
        ("goal_in_polar", 1, "^goal_in_polar must be True or False"),
        ("path_range", "12", "^path_range must be None or \\(min, max\\)"),
        ("path_range", (3.0, 1.0), "^path_range must be \\(min, max\\) with 0 <= min < max"),
        ("waypoint_width", 0.0, "^waypoint_width must be a finite number > 0"),
        ("n_vis_waypoints", 0, "^n_vis_waypoints must be an integer >= 1"),
        ("reward_type", "manhattan", "^reward_type must be one of \\['l2', 'geodesic'\\]"),
        ("termination_config", [1], "^termination_config must be None or a dict"),
    ],
)
def test_each_bad_field_is_refused_by_name(field, value, match):
    with pytest.raises(ValueError, match=match):
        TaskConfig(**{field: value})


def test_replace_checks_again_and_leaves_the_old_value_alone():
    config = TaskConfig(path_range=(1.0, 5.0))
    with pytest.raises(ValueError, match="^path_range"):
        dataclasses.replace(config, path_range="15")
    assert dataclasses.replace(config, path_range=[2, 3]).path_range == (2.0, 3.0)
    assert config.path_range == (1.0, 5.0)


def test_a_config_survives_pickle():
    config = TaskConfig(goal_pos=(1, 2), termination_config={"max_steps": 9})
    assert pickle.loads(pickle.dumps(config)) == config


def test_the_task_keeps_its_arguments_in_its_config():
    task = PointNavigationTask(
        robot_idn=2, goal_tolerance=0.25, path_range=(1, 4), termination_config={"max_steps": 50}
    )
    config = task.config
    assert isinstance(config, TaskConfig)
    assert (config.robot_idn, config.goal_tolerance, config.path_range) == (2, 0.25, (1.0, 4.0))
    assert dict(config.termination_config) == {
        "max_collisions": 500, "max_steps": 50, "fall_height": 0.03
    }
    assert dict(config.reward_config) == dict(PointNavigationTask.default_reward_config)


def test_the_settable_parameters_replace_the_config_and_a_bad_value_changes_nothing():
    task = PointNavigationTask()
    before = task.config
    with pytest.raises(ValueError, match="^path_range"):
        task.path_range = (2.0, 1.0)
    with pytest.raises(ValueError, match="^max_steps"):
        task.max_steps = 0
    assert task.config is before
    task.path_range = (1, 8)
    task.max_steps = 77
    assert task.config.path_range == (1.0, 8.0) and task.path_range == (1.0, 8.0)
    assert task.config.termination_config["max_steps"] == 77
    timeout = task.termination_conditions["timeout"]
    assert isinstance(timeout, Timeout) and timeout.max_steps == 77
    assert before.path_range is None and before.termination_config["max_steps"] == 500


def test_merge_config_refuses_unknown_keys_and_keeps_the_defaults():
    defaults = {"a": 1, "b": 2}
    assert dict(merge_config("x", defaults, {"b": 5})) == {"a": 1, "b": 5}
    assert defaults == {"a": 1, "b": 2}
    with pytest.raises(ValueError, match=r"^x has an unknown key 'c'; valid keys are \['a', 'b'\]"):
        merge_config("x", defaults, {"c": 1})


class _Term:
    def __init__(self, name):
        self.name = name


def test_compose_terms_replaces_in_place_and_appends():
    a, b, b2, c = _Term("a"), _Term("b"), _Term("b"), _Term("c")
    terms = compose_terms("terms", _Term, [a, b], [c, b2])
    assert list(terms) == ["a", "b", "c"]
    assert terms["b"] is b2 and terms["a"] is a
    with pytest.raises(ValueError, match="^terms has two terms named 'c'"):
        compose_terms("terms", _Term, [a], [c, _Term("c")])
    with pytest.raises(ValueError, match="^terms must be None or a sequence"):
        compose_terms("terms", _Term, [a], "c")
