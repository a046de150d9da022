"""LeRobot v3.0 datasets: the one boundary to LeRobot (``lerobot_api``), the feature schema,
the column-wise builder, and building from MCAP logs."""
