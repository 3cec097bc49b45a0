"""A chain's shot history: the shots fired on it before this one (scene key
chain.previous_shots).

Real experiments fire many shots on one chain, and elastic-plastic contacts keep their
flattening from one to the next (rig.model.laws.thornton): a second shot meets stiffer,
pre-flattened contacts and loses less. ``after_shots`` solves the chain's earlier shots,
one after another, each from where the last left the contacts (Chain.after_shot: at rest
again under the static load, with their permanent overlaps, enlarged radii and elastic
limits), at the scene's solver settings and accuracy. Only the contacts' memory carries
over (a chain whose contacts never yield is the same chain); each earlier shot is the
scene's own (striker, magnet), without instruments or noise, so the history is the same
bits for every seed of the shot that follows.
"""
from __future__ import annotations

from rig.model.chain import Chain
from rig.solver.saveat import SaveAt
from rig.solver.solve import solve


def after_shots(chain: Chain, shots: int, solver, save: SaveAt) -> Chain:
    """``chain`` as ``shots`` earlier shots left it (solver: the scene's SolverSettings;
    save: what the shot records, which the accuracy control holds each earlier solve to
    solver.accuracy on, as it holds the shot)."""
    for _ in range(shots):
        chain = chain.after_shot(solve(chain, solver.duration, save=save, method=solver.method,
                                       accuracy=solver.accuracy))
    return chain
