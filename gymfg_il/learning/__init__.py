"""Learning from demonstrations: in-memory data pipeline, behaviour cloning, DAgger."""
