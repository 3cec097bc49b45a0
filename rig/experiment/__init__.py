"""The virtual experiment: scene files, the rig assembled from a scene (parts, gauges, wall
sensor, oscilloscope), the shot, what it measures, and the analysis of scope files and
archives. Imports rig.model, rig.solver, rig.theory and instruments."""
