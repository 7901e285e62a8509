"""Training a policy on the batched engine (needs torch); the network it trains and its
checkpoint file live in :mod:`pointnav_core.policies`.

- :mod:`~pointnav_core.training.ppo`: PPO on :class:`~pointnav_core.vector.VectorPointNavEnv`;
- :mod:`~pointnav_core.training.config`: ``pointnav train``'s config file;
- :mod:`~pointnav_core.training.trainer`: the training run (checkpoints, curve, held-out
  evaluation through :func:`pointnav_core.evaluation.run.evaluate`, resume);
- :mod:`~pointnav_core.training.curve`: the curve's CSV and PNG.

The submodules import torch; this package itself does not, so that ``pointnav`` works
without it.
"""
