"""Training a policy on the batched engine, and its checkpoints (needs torch).

- :mod:`~pointnav_core.training.agent`: the actor-critic MLP and the running statistics;
- :mod:`~pointnav_core.training.ppo`: PPO on :class:`~pointnav_core.vector.VectorPointNavEnv`;
- :mod:`~pointnav_core.training.checkpoint`: one checkpoint file, saved and loaded safely;
- :mod:`~pointnav_core.training.config`: ``pointnav train``'s config file;
- :mod:`~pointnav_core.training.trainer`: the training run (checkpoints, curve, held-out
  evaluation through :func:`pointnav_core.evaluation.run.evaluate`, resume);
- :mod:`~pointnav_core.training.curve`: the curve's CSV and PNG.

The submodules import torch; this package itself does not, so that ``pointnav`` works
without it.
"""
