"""`rig fit --observations`: a scene fitted to observed figures of shots (a pulse's speed,
a gauge reading's peak, a pulse's widths, the number of pulses in a train, the wall's
peak force, an oscillating tail, a ratio of two shots' figures), each with its value,
uncertainty and unit. ``measures``: the figures on (t, signal) arrays; ``kinds``: the
registry of observation kinds and how each is measured on a shot's noise-free truth;
``reading``: the observations file; ``objective``: the fit's residuals."""
