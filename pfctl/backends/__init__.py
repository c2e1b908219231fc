"""Robot-port implementations: the simulated house and the real HSR (later issues)."""
