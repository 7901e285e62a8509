"""A background pool refresh that fails never stops the batched engine (issue 29, point 5).

Its worker killed while building or while idle, or its build raising: the env warns once
with the cause, steps on with the pool it has, and the next ``refresh_pool`` works (on a new
worker when the old one died). Copies and pickles of an env with a refresh pending work, and
a failed copy leaves the original's refresh intact. Pools are tiny: each test's cost is the
worker's start (a spawned interpreter, a second or two).
"""

from __future__ import annotations

import copy
import os
import pickle
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from refresh_faults import StalledBuild, failing_build

from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.scenes import Scene
from pointnav_core.vector import VectorPointNavEnv
from pointnav_core.vector.refresh import PoolRefreshWarning

WAIT = 60.0  # s: far more than a tiny pool's build takes, even on a loaded machine


def small_env() -> VectorPointNavEnv:
    grid = np.zeros((20, 30), np.uint8)  # a walled 3 x 2 m room
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    env = VectorPointNavEnv(2, scene=Scene.from_array(grid, 0.1), seed=0, pool_size=1)
    env.reset(seed=0)
    return env


def goals(env: VectorPointNavEnv) -> list[float]:
    return np.asarray(env.arrays.numpy(env.pool.gx)).tolist()


def steps(env: VectorPointNavEnv, n: int = 3) -> None:
    for _ in range(n):
        obs, *_ = env.step(np.zeros((2, 2)))
        assert np.isfinite(obs).all()


def until(predicate, what: str, limit: float = WAIT) -> None:
    deadline = time.monotonic() + limit
    while not predicate():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


def refresh_works(env: VectorPointNavEnv) -> None:
    """A background refresh brings a new pool in (its episodes first, the old ones after)."""
    before = goals(env)
    env.refresh_pool()
    assert env._refresh.wait(WAIT)
    steps(env, 1)
    assert not env.refresh_pending and len(env.pool) == len(before) + 1
    assert goals(env)[1:] == before


def test_a_worker_killed_mid_build_or_idle_is_reported_once_and_replaced(tmp_path: Path, monkeypatch) -> None:
    env = small_env()
    marker = tmp_path / "started"
    monkeypatch.setattr(env, "_pool_kind", lambda: StalledBuild(marker))
    env.refresh_pool()
    until(marker.exists, "the build to start")
    pid = env._worker.pid
    before = goals(env)
    os.kill(pid, signal.SIGKILL)
    until(lambda: not env._worker.alive(), "the worker to die")
    with pytest.warns(PoolRefreshWarning, match=rf"\(pid {pid}\) was killed by signal SIGKILL while building a pool") as got:
        steps(env, 1)
    assert len(got) == 1 and "__main__" not in str(got[0].message)
    steps(env)  # once only, and on the pool it had (filterwarnings: error)
    assert goals(env) == before and not env.refresh_pending
    env.reset()
    monkeypatch.undo()
    refresh_works(env)  # on a new worker
    # The new worker, killed while idle: the engine never notices; the next refresh does.
    pid, old = env._worker.pid, pid
    assert pid != old
    os.kill(pid, signal.SIGKILL)
    until(lambda: not env._worker.alive(), "the worker to die")
    steps(env)
    with pytest.warns(PoolRefreshWarning, match=rf"\(pid {pid}\) was killed by signal SIGKILL while idle; a new one is started"):
        refresh_works(env)
    worker = env._worker
    assert worker.pid not in (pid, old)
    env.close()
    assert env._worker is None
    with pytest.raises(ProcessLookupError):  # close() stopped and reaped it
        os.kill(worker.pid, 0)


def test_a_build_that_raises_is_reported_once_and_the_worker_kept(monkeypatch) -> None:
    env = small_env()
    monkeypatch.setattr(env, "_pool_kind", lambda: failing_build)
    env.refresh_pool()
    pid = env._worker.pid
    assert env._refresh.wait(WAIT)
    before = goals(env)
    with pytest.warns(PoolRefreshWarning, match=r"build failed in its worker process: .*SamplingError: no goal within path_range"):
        steps(env, 1)
    steps(env)
    env.reset()
    assert goals(env) == before
    monkeypatch.undo()
    refresh_works(env)
    assert env._worker.pid == pid  # the worker lived on
    env.close()


def test_copies_with_a_refresh_pending_work_and_a_failed_copy_hurts_nothing() -> None:
    env = small_env()
    env.refresh_pool()
    assert env.refresh_pending
    for clone in (copy.deepcopy(env), pickle.loads(pickle.dumps(env))):
        # The pending refresh is the original's: the copy goes on with its pool.
        assert not clone.refresh_pending and goals(clone) == goals(env)
        steps(clone)
        clone.refresh_pool(wait=True)
        assert len(clone.pool) == 2
    env.blocker = threading.Lock()  # a copy that fails half-way
    with pytest.raises(TypeError, match="lock"):
        copy.deepcopy(env)
    del env.blocker
    before = goals(env)
    assert env._refresh.wait(WAIT), "the original's refresh hangs"
    steps(env, 1)
    assert not env.refresh_pending and goals(env)[1:] == before
    env.close()


def gone(pid: int) -> bool:
    """Whether process ``pid`` has ended (a zombie waiting for its reaper counts)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except FileNotFoundError:
        return True


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_the_worker_ends_with_the_env_process_even_mid_build(tmp_path: Path) -> None:
    marker = tmp_path / "started"
    code = textwrap.dedent(f"""
        import os, time
        from pathlib import Path
        import numpy as np
        from refresh_faults import StalledBuild
        from pointnav_core.scenes import Scene
        from pointnav_core.vector import VectorPointNavEnv
        grid = np.zeros((20, 30), np.uint8)
        grid[[0, -1], :] = grid[:, [0, -1]] = 1
        env = VectorPointNavEnv(1, scene=Scene.from_array(grid, 0.1), seed=0, pool_size=1)
        env.reset(seed=0)
        env._pool_kind = lambda: StalledBuild(Path({str(marker)!r}))
        env.refresh_pool()
        while not Path({str(marker)!r}).exists():
            time.sleep(0.02)
        print(env._worker.pid, flush=True)
        os.kill(os.getpid(), 9)
    """)
    path = os.pathsep.join(p for p in sys.path if p)
    done = subprocess.run([sys.executable, "-c", code], check=False, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": path})
    assert done.returncode == -signal.SIGKILL, done.stderr
    pid = int(done.stdout.split()[0])
    until(lambda: gone(pid), "the orphaned worker to end", 10.0)  # its build sleeps 120 s
