"""The paper's run: Zhu et al., *Machines* 2023, 11, 357, reproduced and compared.

`run_paper` runs the embedded drill-pipe scene (`paper_scene`: the default
scene of `ballcage.scene.default_scene` recording `PAPER_TABLES`), and writes
into one directory:

- ``<table>.parquet`` and ``scene.toml`` (`Run.write`);
- the paper's figures as PNG: ``fig09_included_angles``, ``fig10_tube_normal``,
  ``fig11_tube_tangential``, ``fig12_key_normal``, ``fig13_key_tangential``
  and ``table3_shape``;
- ``chain.html``: the chain turning in its tube in 3D, links coloured by their
  tube force (`ballcage.view`, at most 120 frames);
- ``comparison.parquet`` and ``comparison.md``: one row per ``[[quantity]]``
  of the shipped reference file ``ballcage/data/paper-2023.toml``, with the
  paper's value, ours, their ratio and a note on how our definition differs
  and on values the paper itself contradicts (``suspect``); plus the rows of
  `EXTRA_ROWS` the file lacks (``range_of_motion_peak_to_peak_mm``, the
  definition of Table 3's range of motion that fits the paper, the included
  angles projected on the bend plane, the inclination where the tube force is
  largest, and ``head_cage_normal_peak_n``, which the paper does not report);
  ``comparison.md`` also says where our forces are largest beside the paper's.

With ``sweeps=True`` it also runs the paper's §4.2–4.3 as one sweep
(`section4`: R = 1.0–2.5 m, 60–120 rpm, and the baseline's run-to-run
spread) into ``sweeps/``, fills the ``sweep_*`` rows, draws Figures 16–17
(`section4_figures`) and checks the paper's ``[[trend]]`` claims (`trends`,
``trends.parquet``).

`comparison(run)` builds the comparison table from any run of the paper scene,
so it can be checked on a short run. Everything is computed from the recorded
tables (``links``, ``hinges``, ``keys``) and the scene's own values
(`Run.scene`); the values by `ballcage.measures` (Table 3's phases and
motion, the peak forces: the same functions as a sweep's summary columns),
the definitions in `DEFINITIONS`, repeated in each row's note.

Modules, one job each: `running` (the scenes and `run_paper`), `definitions`
(the reference file and how each quantity is computed), `compare` (the
comparison table), `places` (where the forces are largest, in words),
`markdown` (``comparison.md``), `figures` (the PNGs),
`section4`, `section4_figures` and `trends` (the §4 sweep; imported on use, as
they load the sweep machinery). Above `ballcage.studies` and `ballcage.view`;
nothing but the CLI imports it.
"""

from ballcage.paper.compare import COMPARISON_SCHEMA, comparison
from ballcage.paper.definitions import EXTRA_ROWS, SWEEPS, TUBE_LINKS, reference
from ballcage.measures.phases import PHASES
from ballcage.paper.figures import FIGURES, KEY_BODIES, write_figures
from ballcage.paper.markdown import comparison_markdown
from ballcage.paper.running import PAPER_TABLES, paper_scene, run_paper

__all__ = [
    "COMPARISON_SCHEMA",
    "EXTRA_ROWS",
    "FIGURES",
    "KEY_BODIES",
    "PAPER_TABLES",
    "PHASES",
    "SWEEPS",
    "TUBE_LINKS",
    "comparison",
    "comparison_markdown",
    "paper_scene",
    "reference",
    "run_paper",
    "write_figures",
]
