"""Benchmark campaigns (``pfctl bench``): many seeded episodes of missions and their variants.

One concept per module:

- :mod:`~pfctl.bench.variants`: ``--vary KEY=V1,V2`` — dotted-key overrides of a mission's YAML
  data, their cross product, readable variant names;
- :mod:`~pfctl.bench.plan`: the campaign — which episodes (mission file, variant, seed) to run,
  and the fingerprint of its configuration;
- :mod:`~pfctl.bench.episode`: one episode as a task a worker runs: the episode function the app
  gives (:mod:`pfctl.app.campaign`: learn the target with the episode's seed, follow or search
  headless, measure) wrapped into a JSON-able record;
- :mod:`~pfctl.bench.runner`: running the tasks in spawned worker processes or as Ray tasks;
- :mod:`~pfctl.bench.results`: the results file (JSON lines, one per finished episode, synced as
  each ends) and resuming from it;
- :mod:`~pfctl.bench.aggregate`: per variant, the mean and 95 % bootstrap interval of each
  metric;
- :mod:`~pfctl.bench.report`: the summary as a terminal table, CSV and Markdown, the episodes as
  CSV;
- :mod:`~pfctl.bench.plots`: box plots per variant.

Nothing here imports ``typer``; :mod:`pfctl.commands.bench` is the command.
"""
