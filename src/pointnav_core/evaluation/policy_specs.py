"""What ``pointnav eval --policy`` accepts: a policy spec turned into a factory
``env -> (observation -> action)`` (the forms are listed in :mod:`pointnav_core.evaluation.run`'s
notes; :func:`make_policy` builds them)."""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from typing import Any

from pointnav_core.errors import ArgumentError
from pointnav_core.policies.spaces import check_spaces

__all__ = ["BUILT_IN", "POLICY_FORMS", "Policy", "PolicyFactory", "make_policy", "policy_file"]

#: The accepted forms of a policy spec, for messages.
POLICY_FORMS = (
    "'oracle', 'orca_robot', 'dwa', MODULE:CALLABLE (a function env -> (observation -> action)), the path to "
    "a checkpoint .pt (pointnav train's), baseline:NAME (a shipped checkpoint) or the path to a Stable-Baselines3 .zip"
)
#: The suffix of a checkpoint (pointnav_core.policies.checkpoint.CHECKPOINT_SUFFIX, which
#: imports torch).
CHECKPOINT_SUFFIX = ".pt"

Policy = Callable[[Any], Any]
PolicyFactory = Callable[[Any], Policy]


# ---------------------------------------------------------------------- policies
def _oracle(env: Any) -> Policy:
    from pointnav_core.policies.oracle import ShortestPathFollower

    follower = ShortestPathFollower(env)
    return lambda _obs: follower.act()


def _orca_robot(env: Any) -> Policy:
    from pointnav_core.policies.crowd import OrcaRobot

    robot = OrcaRobot(env)
    return lambda _obs: robot.act()


def _dwa(env: Any) -> Policy:
    from pointnav_core.policies.crowd import DynamicWindow

    robot = DynamicWindow(env)
    return lambda _obs: robot.act()


#: The built-in policies by name: the oracle (ignores pedestrians) and the crowd baselines.
BUILT_IN = {"oracle": _oracle, "orca_robot": _orca_robot, "dwa": _dwa}


class _SB3Policy:
    """A picklable factory for a Stable-Baselines3 model, loaded once per process."""

    def __init__(self, path: str, algo: str) -> None:
        self.path, self.algo = path, algo
        self._model: Any = None

    def __getstate__(self) -> dict[str, Any]:
        return {"path": self.path, "algo": self.algo, "_model": None}

    @property
    def model(self) -> Any:
        if self._model is None:
            try:
                import stable_baselines3
            except ImportError:
                raise ArgumentError(
                    "an SB3 .zip policy needs stable-baselines3 (pip install 'pointnav-core[rl]')"
                ) from None
            cls = getattr(stable_baselines3, self.algo, None)
            if cls is None:
                raise ArgumentError(
                    f"sb3_algo must name a Stable-Baselines3 algorithm (PPO, SAC, ...), got {self.algo!r}"
                )
            self._model = cls.load(self.path, device="cpu")
        return self._model

    @property
    def flat(self) -> bool:
        from gymnasium import spaces

        return isinstance(self.model.observation_space, spaces.Box)

    def check_env(self, env: Any) -> None:
        """ValueError unless ``env``'s observation and action spaces have the shapes the
        model was trained on (their bounds may differ: they follow the scene's size)."""
        check_spaces(f"policy {self.path!r}", self.model, env)

    def __call__(self, env: Any) -> Policy:
        model = self.model
        return lambda obs: model.predict(obs, deterministic=True)[0]


def policy_file(spec: str) -> str | None:
    """The file a policy spec plays (a checkpoint ``.pt``, a shipped baseline's, an SB3
    ``.zip``), or None for a built-in policy or ``MODULE:CALLABLE``; ValueError for an
    unknown baseline."""
    from pointnav_core.policies.baselines import PREFIX, baseline_path

    if spec.startswith(PREFIX):
        return baseline_path(spec[len(PREFIX):])
    return spec if spec.endswith((CHECKPOINT_SUFFIX, ".zip")) else None


def make_policy(
    spec: str, sb3_algo: str = "PPO", trust_policy_file: bool = False, actions: str | None = None
) -> PolicyFactory:
    """The policy factory named by ``spec`` (see the module notes).

    ``actions`` (``"greedy"`` or ``"sampled"``) sets how a checkpoint ``.pt`` acts, in place
    of the checkpoint's own setting; it is refused for any other policy.

    ``trust_policy_file`` must be True for an SB3 ``.zip``: loading one unpickles Python
    objects stored in it, which can run any code (see the module notes). A checkpoint
    ``.pt`` is plain data and needs no trust; it is read when first used.

    Raises
    ------
    ValueError
        For a spec of no known form, a module or attribute that does not exist, a ``.zip``
        that does not exist or is not trusted, or a ``.pt`` that does not exist (or without
        torch).
    """
    if not isinstance(spec, str) or not spec:
        raise ArgumentError(f"policy must be {POLICY_FORMS}, got {spec!r}")
    file = policy_file(spec)
    if actions is not None and not (file or "").endswith(CHECKPOINT_SUFFIX):
        raise ArgumentError(f"actions ({actions!r}) sets how a checkpoint .pt acts; policy {spec!r} is not one")
    if spec in BUILT_IN:
        return BUILT_IN[spec]
    if file is not None and file.endswith(CHECKPOINT_SUFFIX):
        if not os.path.isfile(file):
            raise ArgumentError(f"policy {spec!r}: no such checkpoint file")
        try:
            from pointnav_core.policies.checkpoint_policy import CheckpointPolicy
        except ImportError:
            raise ArgumentError(f"policy {spec!r}: a checkpoint needs torch (pip install 'pointnav-core[vector]')") from None
        return CheckpointPolicy(file, actions)
    if spec.endswith(".zip"):
        if not os.path.isfile(spec):
            raise ArgumentError(f"policy {spec!r}: no such SB3 .zip file")
        if trust_policy_file is not True:
            raise ArgumentError(
                f"policy {spec!r}: an SB3 .zip holds pickled Python objects that can run any "
                "code when loaded; load only a file you trust, with --trust-policy-file "
                "(trust_policy_file=True)"
            )
        return _SB3Policy(spec, sb3_algo)
    module_name, sep, attr = spec.partition(":")
    if not sep or not module_name or not attr:
        raise ArgumentError(f"unknown policy {spec!r}: expected {POLICY_FORMS}")
    try:
        target: Any = importlib.import_module(module_name)
    except ImportError as err:
        raise ArgumentError(f"policy {spec!r}: cannot import module {module_name!r} ({err})") from None
    for part in attr.split("."):
        if not hasattr(target, part):
            raise ArgumentError(f"policy {spec!r}: module {module_name!r} has no attribute {attr!r}")
        target = getattr(target, part)
    if not callable(target):
        raise ArgumentError(f"policy {spec!r}: {attr!r} is not callable")
    return target
