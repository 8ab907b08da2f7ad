"""feedoracle's comparison side: per-block optimality gap, reports, the CLI and the CI gate."""
