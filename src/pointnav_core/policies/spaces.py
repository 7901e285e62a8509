"""Whether a model fits an env: the shapes of its observation and action spaces against the
env's, with an error that names the env config to pass."""

from __future__ import annotations

from typing import Any

from pointnav_core.errors import ArgumentError

__all__ = ["check_spaces"]


def _shape_of(space: Any) -> Any:
    """What must match between a model's space and an env's: a Box's shape, a Discrete's
    ``n``, a Dict's keys and their shapes."""
    from gymnasium import spaces

    if isinstance(space, spaces.Dict):
        return {key: _shape_of(sub) for key, sub in space.spaces.items()}
    if isinstance(space, spaces.Discrete):
        return f"Discrete({int(space.n)})"
    return tuple(getattr(space, "shape", ()) or ())


def check_spaces(name: str, model: Any, env: Any, advice: str | None = None) -> None:
    """ValueError unless the observation and action spaces of ``model`` (anything with
    ``observation_space`` and ``action_space``) have the shapes of ``env``'s; the message
    names the env config to pass (``--env-config``, ``evaluate(env_config=...)``), or
    says ``advice`` instead."""
    for what in ("observation", "action"):
        want = _shape_of(getattr(model, f"{what}_space"))
        got = _shape_of(getattr(env, f"{what}_space"))
        if want != got:
            raise ArgumentError(
                f"{name} takes {what}s of shape {want}, but the env built for it gives {got}: "
                + (advice or "pass the env config the policy was trained with (pointnav eval "
                   "--env-config FILE, evaluate(env_config=...); pointnav_core.envs.config.EnvConfig)")
            )
