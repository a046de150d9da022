"""Learning from demonstrations: the in-memory data pipeline (``data``), behaviour cloning
(``bc``) and DAgger (``dagger``: the policy flies, the expert labels, the data grows, the
policy is trained again)."""
