"""Learning from demonstrations: a dataset in memory (``data``, checked by ``data_checks``),
the training samples every policy's window declares (``batches``), a behaviour-cloning run's
settings (``config``), its optimisation (``fit``) and what it saves (``saving``), behaviour
cloning itself (``bc``) and DAgger (``dagger``: the policy flies, the expert labels, the
data grows, the policy is trained again)."""
