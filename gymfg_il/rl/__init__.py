"""RL fine-tuning of cloned policies with stable-baselines3's PPO (``train ppo``): the run
(``rl.run``), what it starts from (``rl.start``), the env it trains in (``rl.env``), the
actor-critic around the cloned MLP (``rl.policy``), its evaluations (``rl.judge``) and its
settings (``rl.config``). Needs the ``rl`` extra."""
