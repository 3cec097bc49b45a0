"""Fitting the virtual rig to real shots: scene keys with bounds in units, fitted by
weighted least squares to measured (F_d, V_s) points or to scope records (`rig fit`)."""
