"""Physics-based controllers: PIDs, the autopilots that fly each task, their gains."""
