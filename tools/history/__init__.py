"""pathbench's performance history: a SQLite store of every recorded run (store), the importer of
bench JSON and render reports (importer), change points per series (changes), a static dashboard
(report), the instruction-count preset (instructions) and the backfill over git history (backfill).
Run as `python -m history` with tools/ on sys.path, or as `pathbench history ...`."""
