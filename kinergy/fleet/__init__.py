"""A fleet of robots: every log's energy per cycle on Dask, by robot and by day, with drift.

- :mod:`kinergy.fleet.manifest`: the TOML manifest (robots, models, log globs), log dates;
- :mod:`kinergy.fleet.analysis`: one log -> cycles, measured and predicted energy, breakdown;
- :mod:`kinergy.fleet.run`: the logs as Dask tasks (a local cluster or a user's scheduler);
- :mod:`kinergy.fleet.drift`: step changes and drift of a figure over days;
- :mod:`kinergy.fleet.summary`: by robot and by day, drift flags;
- :mod:`kinergy.fleet.parquet`: the cycles as a Parquet table;
- :mod:`kinergy.fleet.twin`: a twin fleet of logs for tests and benchmarks.
"""

__all__: list[str] = []
