"""Properties of multi-robot episodes in MultiPointNav-v0, explored by a state machine.

The machine builds an env with 2 to 4 robots of any size and drive, each with its own task
(short episodes, small collision budgets), on any registered backend, then resets with any
seed, steps with random actions, drives everyone straight ahead (so that robots meet and
push), and tries illegal steps (an action for a finished agent, a missing action, a step
when no agent is alive). Invariants: robots never overlap, finished agents never come
back, parked robots do not move, removed ones are out of the world, the state and the
observations stay in their spaces.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import event, note, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, rule

from pointnav_core.backends.protocol import available_backends
from pointnav_core.envs._multi_state import STATE_FIELDS
from pointnav_core.envs.fleet import FINISHED_MODES
from pointnav_core.envs.multi_pointnav import MultiPointNavEnv
from pointnav_core.task import TaskStateError
from pointnav_core.testing.strategies import (
    nav_robot_specs,
    nav_scenes,
    nav_task_kwargs,
    robot_actions,
)

# Robots may end a step this much inside each other (the pymunk backend's bound; the
# kinematic backend's is 1e-9 m).
OVERLAP = 1e-3
# A parked robot is braked, not fixed, in a physics backend: how far it may be shoved (m).
PARKED_DRIFT = 1e-4


def forward(spec) -> np.ndarray:
    return np.array([1.0] + [0.0] * (spec.action_dim - 1), dtype=np.float32)


class MultiRobotEpisodes(RuleBasedStateMachine):
    """One multi-robot env through several episodes."""

    @initialize(
        scene=nav_scenes(min_side=24, max_side=30),
        n=st.integers(2, 4),
        backend=st.sampled_from(available_backends()),
        finished=st.sampled_from(FINISHED_MODES),
        flatten=st.booleans(),
        max_cycles=st.integers(1, 40),
        seed=st.integers(0, 2**16),
        data=st.data(),
    )
    def build(self, scene, n, backend, finished, flatten, max_cycles, seed, data):
        robots = [data.draw(nav_robot_specs(), label=f"robot[{i}]") for i in range(n)]
        tasks = [
            {
                **data.draw(nav_task_kwargs(max_steps=30), label=f"task[{i}]"),
                # Small enough that n distinct goals always fit in these rooms.
                "goal_tolerance": data.draw(st.floats(0.1, 0.3), label=f"goal_tolerance[{i}]"),
            }
            for i in range(n)
        ]
        self.env = MultiPointNavEnv(
            scene=scene,
            n_robots=n,
            robot=robots,
            task=tasks,
            backend=backend,
            max_cycles=max_cycles,
            finished=finished,
            flatten_obs=flatten,
        )
        event(f"backend {backend}, finished={finished}")
        self.reset(seed)

    @rule(seed=st.integers(0, 2**16))
    def reset(self, seed):
        env = self.env
        self.obs, infos = env.reset(seed=seed)
        assert env.agents == env.possible_agents == list(self.obs) == list(infos)
        self.finished: set[str] = set()
        self.parked: dict[int, list[float]] = {}
        self.cycles = 0
        tasks, robots = env.tasks, env.robots
        for i in range(len(tasks)):
            for j in range(i):
                if tasks[i].floor == tasks[j].floor:
                    need = max(
                        tasks[i].goal_tolerance + tasks[j].goal_tolerance,
                        robots[i].radius + robots[j].radius,
                        env.scene.floors[tasks[i].floor].resolution,
                    )
                    assert math.dist(tasks[i].goal_xy, tasks[j].goal_xy) >= need

    # ------------------------------------------------------------------ legal steps
    @rule(data=st.data())
    def random_step(self, data):
        if not self.env.agents:
            self._step_without_agents()
            return
        actions = {
            agent: data.draw(
                robot_actions(self.env.robots[int(agent.split("_")[1])], overshoot=0.5),
                label=f"action for {agent}",
            )
            for agent in self.env.agents
        }
        self._step(actions)

    @rule(n=st.integers(1, 20))
    def drive_forward(self, n):
        for _ in range(n):
            if not self.env.agents:
                return
            self._step(
                {a: forward(self.env.robots[int(a.split("_")[1])]) for a in self.env.agents}
            )

    def _step(self, actions):
        env = self.env
        before = list(env.agents)
        obs, rewards, terms, truncs, infos = env.step(actions)
        self.cycles += 1
        for d in (obs, rewards, terms, truncs, infos):
            assert list(d) == before
        ended = [a for a in before if terms[a] or truncs[a]]
        for agent in before:
            assert type(rewards[agent]) is float and math.isfinite(rewards[agent])
            assert type(terms[agent]) is bool and type(truncs[agent]) is bool
            assert env.observation_space(agent).contains(obs[agent])
            if self.cycles >= env.max_cycles:
                assert truncs[agent]
        assert env.agents == [a for a in before if a not in ended]
        for agent in ended:
            i = env.possible_agents.index(agent)
            self.finished.add(agent)
            self.parked[i] = env.backend.get_pose(i)[0].tolist()
            why = [n for n, r in infos[agent]["termination_conditions"].items() if r["done"]]
            event(f"an agent finished by {why or ['max_cycles']}")
            if infos[agent]["termination_conditions"]["falling"]["done"]:
                del self.parked[i]  # it fell: out of the world, not parked
        if any(infos[a]["reward_breakdown"]["collision"] for a in before):
            event("a step with a collision")
        note(f"step {self.cycles}: agents {env.agents}, rewards {rewards}")

    # ------------------------------------------------------------------ illegal steps
    def _step_without_agents(self):
        state = self.env.state()
        with pytest.raises(TaskStateError, match="call reset"):
            self.env.step({})
        np.testing.assert_array_equal(self.env.state(), state)

    # Illegal-step rules need no precondition (a machine whose only enabled rules are
    # unmet preconditions is an invalid example): when they do not apply, they step legally.
    @rule(data=st.data())
    def act_for_a_finished_agent(self, data):
        env = self.env
        if not (self.finished and env.agents):
            self.random_step(data)
            return
        dead = data.draw(st.sampled_from(sorted(self.finished)), label="finished agent")
        actions = {a: forward(env.robots[int(a.split("_")[1])]) for a in [*env.agents, dead]}
        self._illegal(actions, f"action for {dead}, which is not alive")
        event("an action for a finished agent")

    @rule(data=st.data())
    def leave_out_an_alive_agent(self, data):
        env = self.env
        if not env.agents:
            self._step_without_agents()
            return
        missing = data.draw(st.sampled_from(env.agents), label="missing agent")
        actions = {a: forward(env.robots[int(a.split("_")[1])]) for a in env.agents if a != missing}
        self._illegal(actions, f"missing action for {missing}")

    def _illegal(self, actions, match):
        env = self.env
        agents = list(env.agents)
        state = env.state()
        lengths = [t.episode_length for t in env.tasks]
        with pytest.raises(ValueError, match=match):
            env.step(actions)
        assert env.agents == agents
        np.testing.assert_array_equal(env.state(), state)
        assert [t.episode_length for t in env.tasks] == lengths

    # ------------------------------------------------------------------ invariants
    @invariant()
    def finished_agents_never_come_back(self):
        assert not self.finished & set(self.env.agents)
        assert len(self.finished) + len(self.env.agents) == len(self.env.possible_agents)

    @invariant()
    def robots_never_overlap(self):
        env = self.env
        solid = []
        for i, task in enumerate(env.tasks):
            pos = env.backend.get_pose(i)[0]
            if env.backend.is_present(i) and pos[2] >= task.floor_height - 1e-9:
                solid.append((i, pos))
        for a, (i, pi) in enumerate(solid):
            for j, pj in solid[:a]:
                if env.tasks[i].floor == env.tasks[j].floor:
                    gap = math.dist(pi[:2], pj[:2])
                    assert gap >= env.robots[i].radius + env.robots[j].radius - OVERLAP, (i, j)

    @invariant()
    def finished_robots_are_parked_or_gone(self):
        env = self.env
        for i, pose in self.parked.items():
            if env.finished == "park":
                assert env.backend.is_present(i)
                np.testing.assert_allclose(env.backend.get_pose(i)[0], pose, atol=PARKED_DRIFT)
            else:
                assert not env.backend.is_present(i)

    @invariant()
    def state_is_in_its_space(self):
        env = self.env
        state = env.state()
        assert env.state_space.contains(state)
        active = state[STATE_FIELDS.index("active") :: len(STATE_FIELDS)].tolist()
        assert active == [1.0 if a in env.agents else 0.0 for a in env.possible_agents]


MultiRobotEpisodes.TestCase.settings = settings(
    MultiRobotEpisodes.TestCase.settings, deadline=None, stateful_step_count=25
)
TestMultiRobotEpisodes = pytest.mark.long(MultiRobotEpisodes.TestCase)
