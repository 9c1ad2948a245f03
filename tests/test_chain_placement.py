"""Links too long for the centreline start clear of the tube's inner wall (docs/model.md §4).

A 0.5 m link of Ø86 mm in a Ø106 mm tube bent to R = 2 m fits by eq. (9) (up to 0.57 m), but its chord
between two hinges on the centreline has a sagitta of 2 − √(4 − 0.25²) = 15.69 mm, and its inner side
cuts 15.69 + 43 − 53 = 5.69 mm into the inner wall. That is the design chart's cell R = 2 m, L = 0.5 m
with `--tube-id 106`: it started at 4.6 MN per link and stopped at t = 0. The chain is now placed on the
arc of radius R + 5.69 mm.
"""

from __future__ import annotations

import pytest

import ballcage

CELL = ["borehole.curvature_radius=2.0", "pipe.pitch=0.5", "borehole.inner_diameter=0.106",
        "pipe.link_mass=20.025", "pipe.link_inertia=[0.020765, 0.432719, 0.432719]"]


def test_a_link_longer_than_the_centreline_allows_starts_clear_of_the_wall() -> None:
    run = ballcage.simulate({"kind": "drill-pipe"},
                            overrides=[*CELL, "simulation.duration=0.05", 'record.tables=["contacts"]'], progress=False)
    contacts = run.tables["contacts"].to_pandas()
    assert contacts["t"].max() == pytest.approx(0.05), "the run goes on past its start"
    tube = contacts[contacts["pair"].str.endswith("/tube")]
    first = tube[tube["t"] == contacts["t"].min()]
    # Placed on the centreline the links started 5.69 mm into the wall; placed outside it they clear it
    # (the first frame's tube contacts are gravity's, at most tenths of a millimetre).
    assert first.empty or first["depth"].max() < 1e-4, f"{first['depth'].max() * 1e3:.3f} mm at t = 0"
    assert tube["depth"].max() < 1e-3
