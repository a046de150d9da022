"""Online environments: a central state server and clients that each simulate one team."""
