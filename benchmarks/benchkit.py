"""Shared pieces of the benchmarks: the machine, the MovingAI maps, measuring a job alone, VMAS.

:func:`measure` runs one job in a child process and returns its wall time and peak memory,
so that C allocations (scipy, pyastar2d, numpy) count and one job's garbage does not weigh
on the next. Children are forked from a ``forkserver`` started by :func:`start_children`
while the benchmark is still small: a child forked from a large parent would inherit the
parent's size in ``ru_maxrss`` (Linux keeps the pre-``exec`` high-water mark), and the
figures would say more about the parent than about the job.

:func:`vmas_navigation` and :func:`steps_per_second` are the VMAS reference that
``bench_vector.py`` and ``bench_crowd.py`` both measure against, stepped and counted the
same way in both.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import platform
import resource
import sys
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from multiprocessing import forkserver
from pathlib import Path
from typing import Any

__all__ = [
    "MOVINGAI_DIR", "VMAS_LIDAR_RANGE", "Measurement", "machine", "measure", "movingai_maps", "start_children", "steps_per_second",
    "vmas_navigation",
]

#: Where the MovingAI maps are looked for by default (optional: most checkouts lack it).
MOVINGAI_DIR = Path(os.environ.get("POINTNAV_MOVINGAI", "/work/shared/data/movingai"))


def machine() -> str:
    """One line naming the machine: platform, CPU count and Python version."""
    return (
        f"{platform.platform()}, {platform.machine()}, {os.cpu_count()} CPUs, "
        f"python {platform.python_version()}"
    )


def movingai_maps(directory: Path, names: tuple[str, ...]) -> list[Path]:
    """The maps of ``names`` found in ``directory``; prints a note for each one missing."""
    found = []
    for name in names:
        path = Path(directory) / name
        if path.is_file():
            found.append(path)
        else:
            print(f"note: {path} not found, skipping it (the MovingAI maps are optional)")
    return found


def _rss_now_kib() -> int:
    """Resident set size now (KiB), or the peak so far where /proc is missing."""
    try:
        with open("/proc/self/statm") as f:
            pages = int(f.read().split()[1])
        return pages * os.sysconf("SC_PAGE_SIZE") // 1024
    except (OSError, ValueError, IndexError):
        return _peak_kib()


def _peak_kib() -> int:
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak // 1024 if sys.platform == "darwin" else peak  # macOS reports bytes


def _child_hwm_kib(pid: int | None) -> float:
    """Peak resident memory (KiB) of a live child so far, NaN where /proc cannot say."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return float(line.split()[1])
    except (OSError, ValueError, IndexError):
        pass
    return float("nan")


@dataclass
class Measurement:
    """What one measured job did.

    Attributes
    ----------
    laps : dict of str to float
        Seconds from the start of the job to each named point it reached.
    peak_mib : float
        Peak resident memory of the child above its memory after setup, in MiB. For a job
        cut off at the limit, the peak until then (Linux ``VmHWM``; NaN elsewhere).
    result : Any
        What the job returned (None when cut off or failed).
    timed_out : bool
        Whether the job ran past the limit and was killed.
    error : str
        The child's traceback when it failed, else empty.
    """

    laps: dict[str, float] = field(default_factory=dict)
    peak_mib: float = float("nan")
    result: Any = None
    timed_out: bool = False
    error: str = ""


def start_children() -> None:
    """Start the fork server now, while this process is small (see the module notes)."""
    mp.set_start_method("forkserver", force=True)
    forkserver.ensure_running()


def _child(conn: Any, setup: Callable[..., Any], job: Callable[..., Any], args: tuple) -> None:
    try:
        state = setup(*args)
        base = _rss_now_kib()
        conn.send(("ready", 0.0, base))
        t0 = time.perf_counter()

        def lap(name: str) -> None:
            conn.send(("lap", time.perf_counter() - t0, name))

        result = job(state, lap)
        elapsed = time.perf_counter() - t0
        conn.send(("done", elapsed, (max(_peak_kib() - base, 0) / 1024.0, result)))
    except BaseException:  # noqa: BLE001  (the parent prints it)
        conn.send(("error", 0.0, traceback.format_exc()))
    finally:
        conn.close()


def measure(
    setup: Callable[..., Any],
    job: Callable[[Any, Callable[[str], None]], Any],
    args: tuple = (),
    limit: float = 600.0,
    setup_limit: float = 600.0,
) -> Measurement:
    """Run ``job(setup(*args), lap)`` in a child process and measure it.

    ``setup`` (imports, loading the map) is neither timed nor counted in the memory figure.
    ``job`` may call ``lap(name)`` to record the time of intermediate points, which survive
    even when the job is cut off. Both must be module-level functions (they are pickled by
    reference).

    Parameters
    ----------
    setup, job : callable
        The preparation and the measured work.
    args : tuple
        Arguments of ``setup`` (picklable).
    limit : float
        Seconds the job may run before it is killed (> 0).
    setup_limit : float
        Seconds ``setup`` may take (> 0).

    Returns
    -------
    Measurement
        With ``laps["total"]`` the job's wall time when it finished.
    """
    if not limit > 0:
        raise ValueError(f"limit must be > 0 seconds, got {limit}")
    if not setup_limit > 0:
        raise ValueError(f"setup_limit must be > 0 seconds, got {setup_limit}")
    ctx = mp.get_context("forkserver")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(send, setup, job, args), daemon=True)
    proc.start()
    send.close()
    out = Measurement()
    base = None
    deadline = time.monotonic() + setup_limit
    try:
        while True:
            if not recv.poll(max(deadline - time.monotonic(), 0.0)):
                out.timed_out = True
                break
            try:
                kind, seconds, payload = recv.recv()
            except EOFError:
                out.error = f"child exited with code {proc.exitcode} before finishing"
                break
            if kind == "ready":
                base = payload
                deadline = time.monotonic() + limit
            elif kind == "lap":
                out.laps[payload] = seconds
            elif kind == "done":
                out.laps["total"] = seconds
                out.peak_mib, out.result = payload
                break
            else:
                out.error = payload
                break
    finally:
        if proc.is_alive():
            if out.timed_out and base is not None:
                out.peak_mib = max(_child_hwm_kib(proc.pid) - base, 0) / 1024.0
            proc.kill()
        proc.join()
        recv.close()
    return out


def steps_per_second(step: Callable[[], None], steps: int, agents: int, sync: Callable[[], None]) -> float:
    """Agent-steps per second of ``steps`` calls of ``step``, after one call to warm up.

    Parameters
    ----------
    step : callable
        One step of every world (resets included, as the runner does them).
    steps : int
        Calls timed.
    agents : int
        Agent-steps one call counts (worlds x robots; 1 for a single env).
    sync : callable
        Waits for the device (``torch.cuda.synchronize``; a no-op on the CPU).
    """
    step()  # warm up
    sync()
    start = time.perf_counter()
    for _ in range(steps):
        step()
    sync()
    return steps * agents / (time.perf_counter() - start)


def _vmas_crowd(pedestrians: int) -> Any:
    """VMAS's navigation scenario with ``pedestrians`` more agents that carry no lidar.

    Each pedestrian is a VMAS agent as the robots are (a 0.1 m disc with its own goal, in
    VMAS's physics, colliding with the robots and each other, in the robots' lidar, whose
    filter takes every agent) but senses nothing: its observation is its position,
    velocity and goal offset. The rewards and ``done`` still take every agent, as
    navigation's do.
    """
    import torch
    from vmas.scenarios.navigation import Scenario
    from vmas.simulator.core import Agent, Landmark, Sphere

    class Crowd(Scenario):
        def make_world(self, batch_dim: int, device: Any, **kwargs: Any) -> Any:
            world = super().make_world(batch_dim, device, **kwargs)
            for i in range(pedestrians):
                walker = Agent(name=f"pedestrian_{i}", collide=self.collisions, color=(0.5, 0.5, 0.5),
                               shape=Sphere(radius=self.agent_radius))
                walker.pos_rew = torch.zeros(batch_dim, device=device)
                walker.agent_collision_rew = walker.pos_rew.clone()
                world.add_agent(walker)
                walker.goal = Landmark(name=f"pedestrian goal {i}", collide=False, color=(0.5, 0.5, 0.5))
                world.add_landmark(walker.goal)
            return world

        def observation(self, agent: Any) -> Any:
            if agent.sensors:
                return super().observation(agent)
            return torch.cat([agent.state.pos, agent.state.vel, agent.state.pos - agent.goal.state.pos], dim=-1)

    return Crowd()


#: VMAS navigation's lidar range (m): its scenario's ``lidar_range`` default.
VMAS_LIDAR_RANGE = 0.35


def vmas_navigation(num_envs: int, n_agents: int, device: str, pedestrians: int = 0) -> Callable[[], None] | None:
    """One step of VMAS's ``navigation`` scenario, with random continuous actions.

    The actions (eight sets, in turn) are drawn before the clock starts; worlds whose
    ``done`` is set are reset one by one with ``reset_at``, as VMAS does. Every agent carries
    navigation's default lidar (12 rays, 0.35 m, seeing the other agents).

    Parameters
    ----------
    num_envs : int
        Worlds.
    n_agents : int
        Robots per world (navigation's ``n_agents``).
    device : str
        Torch device.
    pedestrians : int
        More agents per world without a lidar (see :func:`_vmas_crowd`), driven by random
        actions as the robots are; 0 for navigation itself.

    Returns
    -------
    callable or None
        The step, or None when VMAS is not installed.
    """
    try:
        import vmas
    except ImportError:
        return None
    import torch

    scenario = _vmas_crowd(pedestrians) if pedestrians else "navigation"
    env = vmas.make_env(scenario, num_envs=num_envs, device=device, continuous_actions=True, n_agents=n_agents, seed=0)
    env.reset()
    gen = torch.Generator(device=device).manual_seed(0)
    actions = [
        [2 * torch.rand((num_envs, env.get_agent_action_size(a)), generator=gen, device=device) - 1 for a in env.agents]
        for _ in range(8)
    ]
    state = {"i": 0}

    def step() -> None:
        _, _, dones, _ = env.step(actions[state["i"] % len(actions)])
        done = dones.nonzero().flatten()
        for index in done.tolist():  # VMAS resets finished worlds one by one
            env.reset_at(index)
        state["i"] += 1

    return step
