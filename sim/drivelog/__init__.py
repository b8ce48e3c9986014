"""Drive logs: overlay of a measured log on the simulation, synthetic test logs from the plant."""
