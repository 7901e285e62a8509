"""Properties of whole navigation episodes: reward bookkeeping, metrics, counters, seeding.

The lifecycle is explored by a RuleBasedStateMachine: resets with any seed, random steps,
goal-seeking steps (so that successes happen), and illegal steps after an episode ended.
Each episode property runs on every registered backend (the test ids are the backend
names); sampling lives in the core, so the same seed also gives the same start and goal on
all of them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import event, given, note, settings
from hypothesis import strategies as st
from hypothesis.stateful import (
    RuleBasedStateMachine,
    initialize,
    invariant,
    rule,
    run_state_machine_as_test,
)

from pointnav_core.backends.protocol import available_backends
from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.scenes import Scene
from pointnav_core.task import TaskState, TaskStateError
from pointnav_core.task.metrics import soft_spl, spl
from pointnav_core.testing.strategies import (
    nav_robot_specs,
    nav_scenes,
    nav_task_kwargs,
    robot_actions,
)
from pointnav_core.transforms import quat2yaw

BACKENDS = available_backends()

distances = st.one_of(st.just(0.0), st.floats(0.0, 1e6), st.just(math.inf))
lengths = st.one_of(st.just(0.0), st.floats(0.0, 1e6))


# ------------------------------------------------------------------------------ metrics


@given(success=st.booleans(), d0=distances, length=lengths)
def test_spl_lies_in_unit_interval(success, d0, length):
    value = spl(success, d0, length)
    assert 0.0 <= value <= 1.0
    assert value == 0.0 or (success and d0 < math.inf)


@given(d_t=distances, d0=distances, length=lengths)
def test_soft_spl_lies_in_unit_interval(d_t, d0, length):
    assert 0.0 <= soft_spl(d_t, d0, length) <= 1.0


@given(d0=distances, length=lengths)
def test_success_at_the_goal_makes_soft_spl_equal_spl(d0, length):
    assert soft_spl(0.0, d0, length) == spl(True, d0, length)


@given(d0=st.floats(1e-3, 1e3), stretch=st.floats(1.0, 1e3))
def test_spl_is_the_inverse_stretch_of_the_path(d0, stretch):
    assert spl(True, d0, d0 * stretch) == pytest.approx(1.0 / stretch, rel=1e-12)


# ------------------------------------------------------------------------------ episodes


def goal_seeking_action(env: PointNavEnv, obs: dict) -> np.ndarray:
    """Turn towards the goal and drive at it (the goal observation, either form)."""
    x, y = (float(v) for v in obs["xy_pos_to_goal"])
    if env.task.goal_in_polar:
        rho, phi = x, y
    else:
        rho, phi = math.hypot(x, y), math.atan2(y, x)
    if env.robot.drive == "holonomic":
        return np.array([math.cos(phi), math.sin(phi), 0.0], dtype=np.float32)
    forward = max(0.0, math.cos(phi)) if abs(phi) < math.pi / 3 else 0.0
    turn = max(-1.0, min(1.0, 2.0 * phi))
    return np.array([forward * min(1.0, 2.0 * rho), turn], dtype=np.float32)


class EpisodeLifecycle(RuleBasedStateMachine):
    """One env on ``backend`` through several episodes; every step's bookkeeping is checked."""

    def __init__(self, backend: str = "kinematic") -> None:
        super().__init__()
        self.backend = backend

    @initialize(
        scene=nav_scenes(), robot=nav_robot_specs(), kwargs=nav_task_kwargs(),
        seed=st.integers(0, 2**16),
    )
    def build(self, scene, robot, kwargs, seed):
        self.env = PointNavEnv(scene=scene, robot=robot, task=kwargs, backend=self.backend)
        self.task = self.env.task
        assert self.task.state is TaskState.IDLE
        self.reset(seed)

    @rule(seed=st.integers(0, 2**16))
    def reset(self, seed):
        self.obs, info = self.env.reset(seed=seed)
        self.running = True
        self.phi0 = self.task.potential
        self.potential_sum = 0.0
        self.collisions = 0
        self.steps = 0
        assert info["episode_length"] == 0 and info["collisions"] == 0

    # Every rule works in every state: after the end of an episode a step must raise and
    # change nothing (checked in _step), so no rule needs a precondition.
    @rule(data=st.data())
    def random_step(self, data):
        self._step(data.draw(robot_actions(self.env.robot, overshoot=0.5), label="action"))

    @rule(data=st.data(), n=st.integers(1, 30))
    def drive_straight(self, data, n):
        action = data.draw(robot_actions(self.env.robot), label="action")
        for _ in range(n):
            self._step(action)
            if not self.running:
                break

    @rule(n=st.integers(1, 15))
    def seek_goal(self, n):
        for _ in range(n):
            self._step(goal_seeking_action(self.env, self.obs))
            if not self.running:
                break

    def _step(self, action):
        if not self.running:
            self._illegal_step(action)
            return
        self._legal_step(action)

    def _illegal_step(self, action):
        pose = self.env.backend.get_pose(self.task.robot_idn)[0]
        length = self.task.episode_length
        with pytest.raises(TaskStateError):
            self.env.step(action)
        assert self.task.state is TaskState.DONE
        assert self.task.episode_length == length
        np.testing.assert_array_equal(self.env.backend.get_pose(self.task.robot_idn)[0], pose)
        event("an illegal step after the end")

    def _legal_step(self, action):
        self.obs, reward, terminated, truncated, info = self.env.step(action)
        self.steps += 1
        breakdown = info["reward_breakdown"]
        # The breakdown sums to the reward, exactly.
        assert sum(breakdown.values()) == reward
        assert math.isfinite(reward)
        # Potential rewards telescope to r_potential * (phi_0 - phi_t).
        self.potential_sum += breakdown["potential"]
        r_potential = self.task.reward_config["r_potential"]
        expected = r_potential * (self.phi0 - self.task.potential)
        assert self.potential_sum == pytest.approx(expected, rel=1e-9, abs=1e-9)
        # The collision counter never decreases; it counts the steps with a contact.
        assert info["collisions"] == self.collisions + self.task.in_contact
        self.collisions = info["collisions"]
        assert 0.0 <= info["spl"] <= 1.0 and 0.0 <= info["soft_spl"] <= 1.0
        assert info["episode_length"] == self.steps
        # Success means the robot is within the tolerance of the goal, now.
        if info["success"]:
            x, y, _ = self.task.get_current_pos(self.env)
            gx, gy, _ = self.task.get_goal_pos()
            assert math.hypot(gx - x, gy - y) < self.task.goal_tolerance
            assert terminated
            assert info["spl"] > 0.0 or info["geodesic_dist"] == math.inf
        assert truncated == info["termination_conditions"]["timeout"]["done"]
        assert info["done"] == (terminated or truncated)
        if self.task.in_contact:
            event("a step with a contact")
        if terminated or truncated:
            self.running = False
            assert self.task.state is TaskState.DONE
            for name, result in info["termination_conditions"].items():
                if result["done"]:
                    event(f"episode ended by {name}")
        note(f"step {self.steps}: reward={reward} info={info}")

    @invariant()
    def observation_is_in_the_space(self):
        assert self.obs in self.env.observation_space


@pytest.mark.parametrize("backend", BACKENDS)
def test_episode_lifecycle(backend):
    # settings() starts from the loaded profile, so max_examples follows dev / ci.
    run_state_machine_as_test(
        lambda: EpisodeLifecycle(backend), settings=settings(deadline=None, stateful_step_count=25)
    )


def copy_scene(scene: Scene) -> Scene:
    """An identical scene that shares no caches with ``scene``."""
    tmap = scene.floors[0]
    return Scene.from_array(np.array(tmap.codes), tmap.resolution, tmap.origin, [tmap.height])


def run_twice(scene_a, scene_b, robot, kwargs, seed, actions, backend):
    a = PointNavEnv(scene=scene_a, robot=robot, task=kwargs, backend=backend)
    b = PointNavEnv(scene=scene_b, robot=robot, task=kwargs, backend=backend)
    obs_a, info_a = a.reset(seed=seed)
    obs_b, info_b = b.reset(seed=seed)
    assert info_a == info_b
    for key in obs_a:
        np.testing.assert_array_equal(obs_a[key], obs_b[key])
    for action in actions:
        step_a, step_b = a.step(action), b.step(action)
        for key in step_a[0]:
            np.testing.assert_array_equal(step_a[0][key], step_b[0][key])
        assert step_a[1:] == step_b[1:]
        if step_a[2] or step_a[3]:
            obs_a, info_a = a.reset()
            obs_b, info_b = b.reset()
            assert info_a == info_b
            for key in obs_a:
                np.testing.assert_array_equal(obs_a[key], obs_b[key])


episodes = {
    "scene": nav_scenes(),
    "robot": nav_robot_specs(),
    "kwargs": nav_task_kwargs(),
    "seed": st.integers(0, 2**16),
    "data": st.data(),
}


@pytest.mark.parametrize("backend", BACKENDS)
@settings(deadline=None)
@given(**episodes)
def test_same_seed_gives_identical_trajectories(backend, scene, robot, kwargs, seed, data):
    actions = data.draw(st.lists(robot_actions(robot, overshoot=0.5), max_size=40), label="actions")
    run_twice(scene, copy_scene(scene), robot, kwargs, seed, actions, backend)


@settings(deadline=None)
@given(scene=nav_scenes(), robot=nav_robot_specs(), kwargs=nav_task_kwargs(), seed=episodes["seed"])
def test_same_seed_gives_the_same_start_and_goal_on_every_backend(scene, robot, kwargs, seed):
    episodes_by_backend = []
    for name in BACKENDS:
        env = PointNavEnv(scene=scene, robot=robot, task=kwargs, backend=name)
        _, info = env.reset(seed=seed)
        position, orientation = env.backend.get_pose(0)
        episode = (
            info["geodesic_dist"],
            position.tolist(),
            env.task.get_goal_pos().tolist(),
            float(quat2yaw(orientation)),
        )
        note(f"{name}: {episode}")
        episodes_by_backend.append(episode)
    first, *others = episodes_by_backend
    for other in others:
        assert other[:3] == first[:3]
        assert math.remainder(other[3] - first[3], 2.0 * math.pi) == pytest.approx(0.0, abs=1e-12)
