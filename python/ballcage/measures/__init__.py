"""Measurements of a drill-pipe run, computed from its recorded tables: one number per quantity.

Modules, one job each: `frames` (per-frame grids of the tables), `phases`
(what the analysis needs from the scene, and Table 3's four phases of the last
revolution), `shape` (the most deformed joint, the hinge with the largest mean
bend over a revolution, and included angles projected on the bend plane),
`motion` (a link's range of motion: its centre's peak-to-peak excursion),
`places` (where the forces are largest: the tube force along the chain, the
key-force peak's hinge, time and drive stage), `sections` (the internal loads
at each link's neck, body and seat from a free-body cut of the rigid link),
`fatigue` (their stress cycles and fatigue life: rainflow, Basquin–Goodman,
Miner; ``fatigue.parquet``) and `quantities` (every quantity of a
sweep case; `DRILL_PIPE`, the plug-in ``ballcage sweep`` and ``ballcage paper
--sweeps`` pass to `ballcage.sweep`, and which ``ballcage chart``'s extends
with the lives). The paper's
comparison (`ballcage.paper`) takes its values from here and adds its notes.
Above `ballcage.run` and `ballcage._links`; below `ballcage.studies` and
`ballcage.paper`, which it never imports.
"""

from ballcage.measures.phases import PHASES, SceneFacts, scene_facts
from ballcage.measures.quantities import DRILL_PIPE, QUANTITIES, DrillPipeQuantities, efficiency, link_columns

__all__ = [
    "DRILL_PIPE",
    "PHASES",
    "QUANTITIES",
    "DrillPipeQuantities",
    "SceneFacts",
    "efficiency",
    "link_columns",
    "scene_facts",
]
