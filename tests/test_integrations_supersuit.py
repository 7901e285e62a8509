"""SuperSuit's PettingZoo wrappers on ``MultiPointNav-v0``, and the vec path it cannot take.

SuperSuit is where PettingZoo users get frame stacking and action clipping; both work on the
multi-robot env as it is. Its route to a Stable-Baselines3 ``VecEnv`` (``black_death_v3``,
``pettingzoo_env_to_vec_env_v1``, ``concat_vec_envs_v1``) does not, because SuperSuit 3.11
ends a world only when every robot is terminated *and* truncated; that is why
``pointnav_core.integrations.sb3.MultiRobotVecEnv`` exists (``docs/decisions.md``).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

with warnings.catch_warnings():
    # SuperSuit 3.11 imports PettingZoo modules through their deprecated creation API.
    warnings.simplefilter("ignore", DeprecationWarning)
    pytest.importorskip("supersuit")  # the dev extra installs it
    from pettingzoo.test import parallel_api_test
    from supersuit import (
        black_death_v3,
        clip_actions_v0,
        concat_vec_envs_v1,
        frame_stack_v1,
        pettingzoo_env_to_vec_env_v1,
    )

from pointnav_core.envs.multi_pointnav import parallel_env  # noqa: E402
from pointnav_core.errors import TaskStateError


def test_frame_stacking_and_action_clipping_pass_the_parallel_api_test():
    env = frame_stack_v1(clip_actions_v0(parallel_env(n_robots=3)), 3)
    observations, _ = env.reset(seed=0)
    assert {agent: obs.shape for agent, obs in observations.items()} == {
        f"robot_{i}": (3 * 8,) for i in range(3)
    }
    parallel_api_test(frame_stack_v1(clip_actions_v0(parallel_env(n_robots=3)), 3), num_cycles=100)


def test_clipped_actions_drive_like_the_clipped_values():
    clipped = clip_actions_v0(parallel_env(n_robots=2))
    plain = parallel_env(n_robots=2)
    clipped.reset(seed=1)
    plain.reset(seed=1)
    big = {agent: np.array([5.0, -5.0], np.float32) for agent in plain.agents}
    unit = {agent: np.array([1.0, -1.0], np.float32) for agent in plain.agents}
    for _ in range(5):
        a, b = clipped.step(big), plain.step(unit)
        for agent in plain.agents:
            np.testing.assert_array_equal(a[0][agent], b[0][agent])
            assert a[1][agent] == b[1][agent]


@pytest.mark.xfail(
    raises=TaskStateError,
    strict=True,
    reason="SuperSuit 3.11 black_death_v3 steps a world whose robots all ended",
)
def test_supersuits_vec_path_steps_a_finished_world():
    venv = concat_vec_envs_v1(
        pettingzoo_env_to_vec_env_v1(black_death_v3(parallel_env(n_robots=2))),
        1,
        num_cpus=0,
        base_class="stable_baselines3",
    )
    venv.reset()
    actions = np.zeros((venv.num_envs, 2), dtype=np.float32)
    for _ in range(2000):  # a world ends within max_cycles=500 steps
        venv.step(actions)
