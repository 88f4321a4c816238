"""`pathbench suite`: the workload suite (issue 28) on every device, recorded into the history,
one page. Standard library only (it runs on the GPU host's plain Python too)."""
