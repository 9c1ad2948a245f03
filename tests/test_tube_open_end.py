"""A link that straddles the guide tube's open end is held by the wall there (docs/model.md §4).

The tube has a wall on its arc only. In two cells of the default design chart
(`ballcage chart`), the chain is longer than the arc and link 8 straddles the
arc's end, pushed sideways into the wall. The level-set line law used to see
only the depth extrema strictly inside the tube: with a maximum–minimum pair of
equal depths just inside the end plane and the true maximum in that plane left
out, the link's two points carried +6.0 MN and −6.0 MN, the link sank 6.4 mm
into the wall, and the runs stopped at t = 1.25 s and 0.70 s. The section in
the end plane is now a maximum of the link's part inside (`Extremum::Mouth`).

Checked on the two cells, each 1.8 s at the shipped default: the run ends at
1.8 s, and no link–tube point is deeper than 1 mm (the deepest is 0.31 mm and
0.41 mm; the paper's scene, 0.27 mm; under the IMPACT law K·δ^2.2, K = 1e5
N/mm^2.2, a point at 1 mm carries 100 kN, seven times the cells' largest
link–tube force, 14.5 kN).
"""

from __future__ import annotations

import pytest

import ballcage

#: The chart's cells (docs/studies.md): curvature radius R [m], joint length L [m], and the link's
#: mass [kg] and inertia [kg·m²] scaled with L as `ballcage chart` scales them.
CELLS = {
    "R = 1.5 m, L = 0.3 m": ["borehole.curvature_radius=1.5", "pipe.pitch=0.3", "pipe.link_mass=12.015",
                             "pipe.link_inertia=[0.012459, 0.097074, 0.097074]"],
    "R = 2.0 m, L = 0.4 m": ["borehole.curvature_radius=2.0", "pipe.pitch=0.4", "pipe.link_mass=16.02",
                             "pipe.link_inertia=[0.016612, 0.224257, 0.224257]"],
}


@pytest.mark.parametrize("cell", sorted(CELLS))
def test_a_link_straddling_the_tube_s_end_stays_out_of_the_wall(cell: str) -> None:
    run = ballcage.simulate({"kind": "drill-pipe"}, overrides=[*CELLS[cell], 'record.tables=["contacts"]'],
                            progress=False)
    contacts = run.tables["contacts"].to_pandas()
    assert contacts["t"].max() == pytest.approx(1.8), "the run reaches the scene's 1.8 s"
    tube = contacts[contacts["pair"].str.endswith("/tube")]
    assert len(tube) > 1000, "the links touch the tube throughout"
    # The test's window: the contact sits tenths of a millimetre deep; without the open end's maximum
    # link 8 sank 6.4 mm (and the run stopped).
    deepest = tube["depth"].max()
    assert 1e-4 < deepest < 1e-3, f"deepest link–tube point {deepest * 1e3:.3f} mm"
