"""One module per CLI command group: parse, load the mission, call core/backends, report."""
