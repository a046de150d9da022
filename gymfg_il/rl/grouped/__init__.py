"""The grouped sampler (``train ppo --sampler grouped``, the default): PPO's rollouts
sampled where the envs run.

stable-baselines3's own loop (``--sampler sb3``) runs one process per env, steps them in
lockstep with the trainer and runs the policy in the trainer between steps: every step costs
a pipe round trip per env and leaves the cores idle while the policy runs. Here:

- ``vec``: ``GroupedVecEnv``, one process per core, each stepping its group of envs (a step
  is one message per process), with ``SubprocVecEnv``'s semantics env by env;
- ``sampling``: each process samples its envs' actions itself for a whole rollout, as
  ``collect_rollouts`` would, from a copy of the policy that gets the weights once a rollout;
- ``forward``: that copy as numpy functions (``NumpyActorCritic``), cheaper than torch on a
  few rows;
- ``algorithm``: ``GroupedPPO``, which fills stable-baselines3's rollout buffer from the
  arrays the processes return.

PPO's update is untouched. ``python -m benchmarks.rl`` measures the sampling rate against
the bare physics.
"""
