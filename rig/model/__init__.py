"""The physical parts of the rig and the chain they form: materials, beads, striker, wall,
holder and ring magnet, contact laws (the one source of their kernel codes), and the
chain's static equilibrium and probes. Imports only rig's foundation (errors, units, memo)."""
