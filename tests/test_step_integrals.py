"""Integrals over a run are sums over the integrator's steps, not over the frames a user chose to record.

With adaptive steps the `wear` table (friction work, sliding, Archard's load × distance, the largest Hertz
pressure) and the `energy` table's works are summed at the end of every step the controller accepts, by the
trapezoidal rule, and interpolated to the frames (docs/engine.md, "Energy balance"). So the same trajectory
(``simulation.max_step`` fixed) recorded every 1 ms and every 10 ms gives the same tables.

The peaks likewise: the `summary` table's ``normal_peak`` and ``tangential_peak`` and the links' largest tube
force (``links.tube_normal_max``, read by every headline peak) are the largest at any stage of the integrator's
accepted steps.

Measured on the code before (2026-11-27, commit b203beb), which summed the rates at the frames times the output
interval and took the peaks at the frames, for this scene (ideal-CV hinges, 0.3 s, window 0.1-0.3 s): the summed
friction work was 45.52 J with 1 ms frames and 49.43 J with 10 ms frames (+8.6 %); the largest pressure 4.67 GPa
at both, against 5.97 GPa with 0.1 ms frames (an impact between two 1 ms frames); link 9's largest tube force
3 078 N with 1 ms frames and 1 641 N with 10 ms frames, against 8 715 N at the stages now. The closed forms (a
ball sliding into rolling loses m·v₀²/7; a Hertz impact's peak force) are checked in
crates/ballcage-core/tests/energy_balance.rs and impulses.rs.
"""

from __future__ import annotations

import numpy as np
import pytest

import ballcage
from ballcage._links import link_tube_forces

SCENE = ['pipe.hinge="ideal-cv"', "simulation.duration=0.3", "record.summary_window=[0.1, 0.3]", "simulation.max_step=1e-3"]
WEAR_INTEGRALS = ("friction_work", "sliding_distance", "normal_sliding", "wear_volume", "pressure_peak", "pressure_peak_t")
WORKS = ("drive_work", "load_work", "friction_work", "damping_work", "joint_work")


@pytest.fixture(scope="module")
def runs() -> tuple[ballcage.Run, ballcage.Run]:
    def run(every: float) -> ballcage.Run:
        overrides = [*SCENE, f"simulation.output_interval={every}", 'record.tables=["energy", "wear", "links", "summary"]']
        return ballcage.simulate({"kind": "drill-pipe"}, overrides=overrides, progress=False)

    return run(1e-3), run(1e-2)


def test_the_wear_table_does_not_depend_on_the_frames_recorded(runs):
    fine, coarse = runs
    assert fine.metadata["ballcage.accepted_steps"] == coarse.metadata["ballcage.accepted_steps"]
    a, b = fine.tables["wear"], coarse.tables["wear"]
    assert a.column("pair").to_pylist() == b.column("pair").to_pylist()
    for name in WEAR_INTEGRALS:
        x = np.asarray(a.column(name).to_numpy(zero_copy_only=False), dtype=float)
        y = np.asarray(b.column(name).to_numpy(zero_copy_only=False), dtype=float)
        np.testing.assert_allclose(y, x, rtol=1e-12, atol=0.0, err_msg=name)
    # The window holds real sliding: the equality above is not that of two empty sums.
    assert float(np.sum(a.column("friction_work").to_numpy())) > 10.0


def test_the_works_at_common_frames_do_not_depend_on_the_frames_recorded(runs):
    fine, coarse = runs
    ef, ec = fine.tables["energy"], coarse.tables["energy"]
    tf, tc = ef.column("t").to_numpy(), ec.column("t").to_numpy()
    index = np.rint(tc / 1e-3).astype(int)
    np.testing.assert_allclose(tf[index], tc, rtol=0, atol=1e-12)
    for name in WORKS:
        x, y = ef.column(name).to_numpy()[index], ec.column(name).to_numpy()
        scale = max(float(np.max(np.abs(x))), 1e-9)
        np.testing.assert_allclose(y, x, rtol=0, atol=1e-12 * scale, err_msg=name)
    # The drive has done work by the first 10 ms frame and keeps doing it.
    drive = ec.column("drive_work").to_numpy()
    assert drive[1] > 0 and np.all(np.diff(drive[1:]) > 0)


def test_the_peaks_do_not_depend_on_the_frames_recorded(runs):
    fine, coarse = runs
    a, b = link_tube_forces(fine), link_tube_forces(coarse)
    assert a is not None and b is not None
    assert b.normal_peak == pytest.approx(a.normal_peak, rel=1e-12, abs=0.0)
    sa = {r["pair"]: r for r in fine.tables["summary"].to_pylist()}
    sb = {r["pair"]: r for r in coarse.tables["summary"].to_pylist()}
    for pair, row in sa.items():
        for name in ("normal_peak", "tangential_peak"):
            assert sb[pair][name] == pytest.approx(row[name], rel=1e-12, abs=0.0), (pair, name)
    # The links' peaks are the summary's for their tube pairs, and the chain does press the tube.
    for k, peak in a.normal_peak.items():
        assert peak == pytest.approx(sa[f"link{k:02d}/tube"]["normal_peak"], rel=1e-12), k
    assert max(a.normal_peak.values()) > 1000.0
