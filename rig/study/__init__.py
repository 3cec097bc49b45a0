"""Studies over many shots: distributions, sweeps, Monte Carlo (spec, batches, storage,
executors, report) and the reproduction of the published study. Imports every layer below."""
