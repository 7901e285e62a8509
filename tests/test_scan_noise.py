"""Counter-based scan noise: the hash by hand, its statistics, and the same draws in every engine."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from pointnav_core.envs.pointnav import PointNavEnv
from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.sensors.noise import (
    DROPOUT,
    NOISE,
    episode_key,
    mix,
    normals,
    scan_noise,
    seed_entropy,
    uniforms,
)
from pointnav_core.vector import VectorPointNavEnv

M64 = 0xFFFFFFFFFFFFFFFF
GOLDEN = 0x9E3779B97F4A7C15


def _finalise(z: int) -> int:
    """splitmix64's finaliser with plain Python ints."""
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M64
    return z ^ (z >> 31)


def _mix(h: int, v: int) -> int:
    return _finalise(_finalise((h + GOLDEN) & M64) ^ v)


def test_hash_by_hand() -> None:
    # SplitMix64 seeded with 0 first returns 0xE220A8397B1DCDAF (its reference output):
    # that is the finaliser of the golden gamma, the inner step of mix(0, .).
    assert _finalise(GOLDEN) == 0xE220A8397B1DCDAF
    assert int(mix(0, 0)) == _finalise(0xE220A8397B1DCDAF)
    # One full draw: episode 2 of seed 5, robot 1, step 3, ray 4, the noise channel.
    h = _mix(_mix(_mix(_mix(_mix(5, 2), 1), 3), 4), NOISE)
    u = ((h >> 11) + 0.5) / 2.0**53
    assert float(uniforms(episode_key(5, 2), 1, 3, 4, NOISE)) == u
    assert float(normals(episode_key(5, 2), 1, 3, 4)) == pytest.approx(stats.norm.ppf(u), abs=1e-12)
    # Seeds wrap modulo 2**64 (negative ints as their two's complement); seeds and counts do not commute.
    assert int(mix(2**64 + 7, 1)) == int(mix(7, 1)) == _mix(7, 1)
    assert int(mix(-1, 0)) == _mix(M64, 0)
    assert int(mix(0, 1)) != int(mix(1, 0))


def test_draws_are_uniform_and_normal() -> None:
    ep = episode_key(np.arange(40, dtype=np.uint64)[:, None, None], 0)
    u = uniforms(ep, np.arange(5)[None, :, None], 7, np.arange(100)[None, None, :], DROPOUT).ravel()
    assert ((u > 0.0) & (u < 1.0)).all()
    assert stats.kstest(u, "uniform").pvalue > 1e-3
    z = normals(ep, np.arange(5)[None, :, None], 7, np.arange(100)[None, None, :]).ravel()
    assert stats.kstest(z, "norm").pvalue > 1e-3
    assert abs(z.mean()) < 0.05 and abs(z.std() - 1.0) < 0.05
    # scan_noise: noise_std times the normals of the noise channel; dropout at its rate.
    noise, lost = scan_noise(ep, np.arange(5)[None, :, None], np.full((1, 1, 1), 7), 100, 0.3, 0.25)
    np.testing.assert_allclose(noise.ravel(), 0.3 * z, rtol=0, atol=1e-15)
    u = uniforms(ep, np.arange(5)[None, :, None], 7, np.arange(100)[None, None, :], DROPOUT)
    np.testing.assert_array_equal(lost, u < 0.25)
    assert abs(lost.mean() - 0.25) < 0.02


@pytest.mark.parametrize("axis", ["seed", "episode", "robot", "step", "ray", "channel"])
def test_neighbouring_keys_are_uncorrelated(axis: str) -> None:
    n = 20_000
    base, episode, robot, step, ray = np.arange(n, dtype=np.uint64) * 7919, 3, 1, 11, 5
    keys = {"seed": base, "episode": episode, "robot": robot, "step": step, "ray": ray}

    def draw(shift: int) -> np.ndarray:
        k = dict(keys)
        if axis != "channel":
            k[axis] = k[axis] + np.uint64(shift) if axis == "seed" else k[axis] + shift
        return uniforms(episode_key(k["seed"], k["episode"]), k["robot"], k["step"], k["ray"],
                        DROPOUT if axis == "channel" and shift else NOISE)

    a, b = draw(0), draw(1)
    # Independent uniforms: the correlation of n pairs is within 4.5 / sqrt(n) of 0.
    assert abs(np.corrcoef(a, b)[0, 1]) < 4.5 / math.sqrt(n)
    assert stats.kstest(b - a, stats.triang(c=0.5, loc=-1.0, scale=2.0).cdf).pvalue > 1e-3


def test_seed_entropy_is_the_reset_seed() -> None:
    seq, base = seed_entropy(np.random.default_rng(12))
    assert base == 12 and isinstance(seq, np.random.SeedSequence)
    assert seed_entropy(np.random.default_rng(2**70 + 3))[1] == 3
    _, a = seed_entropy(np.random.default_rng([1, 2]))
    _, b = seed_entropy(np.random.default_rng([2, 1]))
    assert a != b


def _room() -> Scene:
    grid = np.zeros((20, 30), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    grid[8:12, 14:16] = OBSTACLE
    return Scene.from_array(grid, 0.1)


TASK = {"initial_pos": [0.6, 1.0], "initial_quat": [0.0, 0.0, 0.0, 1.0], "goal_pos": [2.4, 1.0],
        "termination_config": {"max_steps": 6}}
NOISY = {"scan": {"n_rays": 24, "max_range": 2.0, "noise_std": 0.05, "dropout": 0.2}}


def test_single_env_counts_its_episodes_from_the_seeded_reset() -> None:
    env = PointNavEnv(scene=_room(), task=TASK, sensors=NOISY)
    first = env.reset(seed=4)[0]["scan"]
    second = env.reset()[0]["scan"]
    again = env.reset(seed=4)[0]["scan"]
    np.testing.assert_array_equal(first, again)  # the same start: episode 0 of seed 4 both times
    assert not np.array_equal(first, second)  # the same start, episode 1: other draws


def test_world_w_reads_the_single_env_reset_with_seed_s_plus_w() -> None:
    episodes = [([0.6, 1.0], 0.0, [2.4, 1.0])] * 3
    venv = VectorPointNavEnv(3, scene=_room(), task={"termination_config": {"max_steps": 6}}, sensors=NOISY, seed=10)
    obs, _ = venv.reset(options={"episodes": episodes})
    single = PointNavEnv(scene=_room(), task=TASK, sensors=NOISY, flatten_obs=True)
    for w in range(3):
        np.testing.assert_allclose(obs[w], single.reset(seed=10 + w)[0], rtol=0, atol=1e-6)
        assert not np.allclose(obs[w], single.reset(seed=11 + w)[0], rtol=0, atol=1e-3)
    # The same start in every world: only the keys tell the worlds' scans apart.
    assert not np.array_equal(obs[0], obs[1])
    # A reset without a seed begins episode 1 in every world, as a single env's next reset.
    obs, _ = venv.reset(options={"episodes": episodes})
    single.reset(seed=12)
    np.testing.assert_allclose(obs[2], single.reset()[0], rtol=0, atol=1e-6)


@pytest.mark.parametrize("n_robots", [1, 3])
def test_noise_changes_no_episode(n_robots: int) -> None:
    rng = np.random.default_rng(5)
    actions = rng.uniform(-1.0, 1.0, (40, 4, n_robots, 2))
    if n_robots == 1:
        actions = actions[:, :, 0]

    def run(sensors: dict) -> list:
        env = VectorPointNavEnv(4, n_robots=n_robots, scene=_room(), sensors=sensors, seed=3, pool_size=3,
                                task={"termination_config": {"max_steps": 9}})
        obs, _ = env.reset()
        out = [obs[..., :8]]
        for act in actions:
            obs, reward, term, trunc, info = env.step(act)
            out += [obs[..., :8], reward, term, trunc, info["autoreset"]]
        return out

    noisy, exact = run(NOISY), run({"scan": {"n_rays": 24, "max_range": 2.0}})
    assert sum(int(np.sum(v)) for v in exact[5::5]) > 0  # autoresets happened
    for a, b in zip(noisy, exact):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(run(NOISY)[0], noisy[0])

    def single(sensors: dict) -> list:
        env = PointNavEnv(scene=_room(), sensors=sensors, task={"termination_config": {"max_steps": 9}})
        env.reset(seed=8)
        out = []
        for act in actions[:, 0].reshape(40, -1)[:, :2]:
            _, reward, term, trunc, _ = env.step(act.astype(np.float32))
            out += [env.backend.get_pose(0)[0].tolist(), reward, term, trunc]
            if term or trunc:
                env.reset()
        return out

    assert single(NOISY) == single({"scan": {"n_rays": 24, "max_range": 2.0}})


def test_scan_noise_refuses_an_unknown_method() -> None:
    with pytest.raises(ValueError, match="method must be one of 'auto', 'array', 'numba', got 'gpu'"):
        scan_noise(episode_key(1, 0), 0, 0, 4, 0.1, 0.0, method="gpu")


@pytest.mark.parametrize("method", ["array", "auto"])
def test_scan_noise_is_the_hash_by_hand(method: str) -> None:
    # Two worlds, two robots, three rays: every element against splitmix64 with Python ints.
    episode = np.array([[[5]], [[2**64 - 3]]], dtype=np.uint64)
    robot, step = np.arange(2)[None, :, None], np.array([[[0], [7]], [[41], [3]]])
    noise, lost = scan_noise(episode, robot, step, 3, 0.2, 0.4, method=method)
    for i, j, r in np.ndindex(2, 2, 3):
        keys = (int(episode[i, 0, 0]), j, int(step[i, j, 0]), r)
        u_noise, u_lost = (((_mix(_mix(_mix(_mix(*keys[:2]), keys[2]), r), c) >> 11) + 0.5) / 2.0**53
                           for c in (NOISE, DROPOUT))
        assert noise[i, j, r] == 0.2 * stats.norm.ppf(u_noise)
        assert bool(lost[i, j, r]) == (u_lost < 0.4)
