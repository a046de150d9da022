"""Behaviour-cloning policies, LeRobot-style: ``configuration_<name>`` + ``modeling_<name>``
per policy, found by name through ``factory``."""
