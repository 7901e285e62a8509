"""What acts in an env: the privileged shortest-path follower (the oracle baseline), a
trained network and its checkpoint file, the policy that plays a checkpoint, and the check
that a model's spaces fit an env.

=========================  ==================================================================
Module                     What it owns
=========================  ==================================================================
``oracle``                 :class:`ShortestPathFollower`, the exact-geodesic oracle
``network``                the actor-critic MLP and its running observation statistics (torch)
``checkpoint``             one checkpoint file (``.pt``), saved and loaded safely (torch)
``checkpoint_policy``      :class:`CheckpointPolicy`: a checkpoint played as a policy
``spaces``                 :func:`check_spaces`: a model's spaces against an env's
=========================  ==================================================================

The torch modules load on first use, so that the oracle works without torch.
"""

from pointnav_core.policies.checkpoint_policy import CheckpointPolicy
from pointnav_core.policies.oracle import ShortestPathFollower
from pointnav_core.policies.spaces import check_spaces

__all__ = ["CheckpointPolicy", "ShortestPathFollower", "check_spaces"]
