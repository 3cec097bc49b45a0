"""The measurement side of the rig: gauges, wall sensor, oscilloscope, scope files,
archive and analysis. Works on plain arrays and records and never imports ``rig``."""
