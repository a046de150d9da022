"""LeRobot v3.0 datasets: the feature schema, the builder, and building from MCAP logs."""
