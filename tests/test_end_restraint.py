"""The chain's end restraint (issue 25, item 2; docs/buckling.md §3a, docs/paper.md).

1. `pipe.lower_end = "axially-free"` and `load.axial_force` from the CLI (`--set`) and
   from Python (`ballcage.simulate(..., overrides=[...])`), with their unit in
   `scene show` and errors that name the field, the value and the reason.
2. The buckling criterion's axial-force and play terms against hand calculations.
3. The axial-force term against simulation: a straight chain of 6 ideal-CV links
   pulled with 5 kN stays straight at 0.9 × the predicted torque and coils onto the
   wall at 1.1 × (a threshold wrong by 2×, or eq. 3.7's long-chain value, fails one
   side). About 5 s on 2 cores.
"""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

import ballcage
from ballcage.buckling import buckling, finite_greenhill, play_excursion, simulate_check

FREE = ['pipe.lower_end="axially-free"']


def test_scene_show_prints_the_new_fields_with_their_units():
    out = subprocess.run(
        [sys.executable, "-m", "ballcage", "scene", "show", "--set", FREE[0], "--set", "load.axial_force=-1000"],
        capture_output=True, text=True, check=True,
    ).stdout
    assert 'lower_end = "axially-free"' in out
    assert "axial_force = -1000.0  # N" in out


def test_an_axial_force_on_the_fixed_end_is_refused_by_field_value_and_reason():
    run = subprocess.run(
        [sys.executable, "-m", "ballcage", "scene", "show", "--set", "load.axial_force=1000"],
        capture_output=True, text=True,
    )
    assert run.returncode != 0
    assert "load.axial_force" in run.stderr and "1000" in run.stderr and "axially-free" in run.stderr


def test_a_pulled_free_end_moves_by_the_hinge_springs_in_series_from_python():
    # 3 ideal-CV links, no gravity, no torque, straight tube: 4 hinge springs of 1e9 N/m in
    # series under 2 kN stretch 4·F/k = 8 µm, along the tube's end tangent: on R = 100 km the
    # chain hangs at the top of the arc, so that is downhole, −z.
    run = ballcage.simulate(
        ballcage.scene.default_scene(),
        overrides=[
            *FREE, "load.axial_force=2000", 'pipe.hinge="ideal-cv"', "pipe.joints=3", "load.resisting_moment=0",
            "load.ramp=0.05", "borehole.curvature_radius=1e5", "drive.speed_rpm=0", "world.gravity=0",
            "simulation.duration=0.15", "simulation.output_interval=0.05", 'record.tables=["bodies"]',
        ],
        progress=False,
    )
    rows = run.tables["bodies"].to_pydict()
    z = [p for p, b in zip(rows["pos_z"], rows["body"], strict=True) if b == "lower"]
    assert z[0] - z[-1] == pytest.approx(4 * 2000.0 / 1e9, rel=5e-3)


def test_the_axial_force_and_the_play_enter_the_criterion_as_calculated_by_hand():
    # Tension N alone: Greenhill's discrete torque min (l·N)/sin θ = N·l at a quarter turn per link.
    pulled = buckling(overrides=[*FREE, "load.axial_force=1000"])
    assert pulled.terms["axial tension [N]"] == 1000.0
    assert pulled.greenhill == pytest.approx(1000.0 * 0.2, rel=1e-9)
    assert pulled.play_excursion == math.inf  # a free end lets the global mode coil freely
    assert buckling(overrides=[*FREE, "load.axial_force=-1000"]).greenhill == 0.0  # compression holds nothing
    fixed = buckling()  # the fixed end carries no axial force: no Greenhill term
    assert fixed.terms["axial tension [N]"] == 0.0 and fixed.greenhill == math.inf
    # The play: 13 hinges × 0.12 mm = 1.56 mm of excess length for 12 links of 0.2 m; the quarter-turn
    # helix through the end hinges loses a²/l per link: a = √(1.56e-3 · 0.2 / 12) = 5.099 mm, so the
    # hinges reach 2a = 10.198 mm off the axis, short of the 15 mm clearance.
    held = buckling(hinge_play=1.2e-4)
    assert held.play_excursion == pytest.approx(2 * math.sqrt(1.56e-3 * 0.2 / 12), rel=1e-12)
    assert held.play_excursion == pytest.approx(0.010198, abs=1e-6)
    assert play_excursion(12, 0.2, 0.0) == 0.0
    with pytest.raises(ValueError, match="hinge_play = -0.001 m"):
        buckling(hinge_play=-1e-3)


def test_the_finite_chain_threshold_matches_its_closed_forms():
    # eq. 3.9: 3 links under tension alone: √3·N·l; 4 links: √(8/5)·N·l; the long-chain limit is
    # eq. 3.7's N·l; stiffness alone on 3 links: √20·k_b (hand solution of the 4 × 4 system).
    assert finite_greenhill(3, 0.2, 1000.0, 0.0) == pytest.approx(math.sqrt(3) * 200.0, rel=1e-9)
    assert finite_greenhill(4, 0.2, 1000.0, 0.0) == pytest.approx(math.sqrt(8 / 5) * 200.0, rel=1e-9)
    assert finite_greenhill(200, 0.2, 1000.0, 0.0) == pytest.approx(200.0, rel=1e-3)
    assert finite_greenhill(3, 0.2, 0.0, 1.0) == pytest.approx(math.sqrt(20), rel=1e-9)
    assert finite_greenhill(12, 0.2, -1000.0, 0.0) == 0.0


def test_the_tension_threshold_brackets_the_simulated_one_within_10_percent():
    # A nearly straight tube (R = 1 km: the end hinges' swing circles are 20 µm), no gravity,
    # 6 ideal-CV links, the lower end free and pulled with 5 kN: only the global mode can take the
    # chain to the wall. Predicted (eq. 3.9) 1.1154·N·l = 1115 N·m; measured between 1100 and
    # 1150 N·m (docs/buckling.md §3a). Eq. 3.7's N·l = 1000 N·m would fail the upper bracket.
    scene = [
        'pipe.hinge="ideal-cv"', "pipe.joints=6", "borehole.curvature_radius=1000", "world.gravity=0",
        *FREE, "load.axial_force=5000",
    ]
    predicted = buckling(overrides=scene).finite_greenhill
    assert predicted == pytest.approx(1115.38, rel=1e-5)
    below, above = simulate_check(None, [0.9 * predicted, 1.1 * predicted], overrides=scene)
    assert below.wall_force == 0.0 and below.lateral_offset < 1e-3, below
    assert above.wall_force > 20.0 and above.lateral_offset > 5e-3, above
