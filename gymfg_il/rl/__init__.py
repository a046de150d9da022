"""Reinforcement learning with stable-baselines3's PPO (``train ppo``): fine-tuning a cloned
MLP policy in its own flight, or learning from scratch. Needs the ``rl`` extra.

Laid out along stable-baselines3's lines:

- ``config``: the run's settings (``PPORunConfig``: the flight options, the run, PPO's own);
  ``hyperparams`` and ``hyperparams.toml``, PPO's own settings per task;
- ``algorithm``: what the fine-tuning changes in PPO (``FineTunePPO``: the critic's warm-up,
  the actor's ramp, the anchor); ``model``, the model a run trains (``make_model``);
- ``policy``: the actor-critic around the cloned MLP (``AnchoredPolicy``);
- ``envs``: the training envs and their vector env; ``reward``, what PPO maximises, composed
  in one place;
- ``callbacks``: the evaluations during training; ``judge``, how an actor is evaluated and
  the kept one chosen;
- ``start``, ``folders``, ``saving``: what a run starts from, where it writes, what it saves;
- ``run``: a run from start to saved policy (``train_ppo``);
- ``grouped``: the grouped sampler (``--sampler grouped``, the default), rollouts sampled in
  the env processes.
"""
