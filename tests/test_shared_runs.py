"""Cases that share a run (`Scene.engine_digest`, `ballcage.studies.sweep_run.shared_runs`).

Two scenes with the same engine digest must record bitwise the same tables:
a sweep runs only the first and computes the others' quantities from its
run with their own scene. Checked here:

- for every registry parameter (`ballcage.proposals`) at both ends of its
  range, on both hinge models: where the digest is the base's, a real run
  records bitwise the base's tables (the digest leaves nothing out that
  the engine uses); a digest that covered too little would fail here;
- a sensitivity study's shared cases hold what running them gives (the
  fatigue life, which ``fatigue.neck_scf`` moves, and every other quantity);
  the contacts the lives read are not kept;
- a lost record of a shared case is computed again on resume.
"""

from __future__ import annotations

import pytest

import ballcage
from ballcage.scene import default_scene
from ballcage.studies.sensitivity_quantities import DRILL_PIPE_SENSITIVITY
from ballcage.studies.sensitivity_run import sensitivity
from ballcage.studies.sweep_case import read_case_run, record_path
from ballcage.studies.sweep_spec import partition_name

SHORT = "simulation.duration=0.004"  # s: a few steps of every contact, enough to tell two runs apart


def _digest(*overrides: str) -> str:
    return default_scene(list(overrides)).engine_digest()


@pytest.mark.parametrize("hinge", ["ball-keys", "ideal-cv"])
def test_a_parameter_with_the_base_digest_records_bitwise_the_base_tables(hinge: str) -> None:
    base = (f'pipe.hinge="{hinge}"', SHORT)
    reference = ballcage.simulate(default_scene(list(base)), progress=False).tables
    same, differ = [], []
    for row in ballcage.proposals().to_pylist():
        for end in (row["low"], row["high"]):
            if end == row["default"]:
                continue
            setting = f"{row['key']}={end!r}"
            (same if _digest(*base, setting) == _digest(*base) else differ).append(setting)
    for setting in same:
        tables = ballcage.simulate(default_scene([*base, setting]), progress=False).tables
        assert tables.keys() == reference.keys(), setting
        for name, table in tables.items():
            assert table.equals(reference[name]), (setting, name)
    keys = {s.split("=")[0] for s in same}
    # The fatigue section enters no run; the other hinge model's stiffnesses none of this one's.
    assert {k for k in keys if k.startswith("fatigue.")}
    assert any(k.startswith("pipe.ideal_cv." if hinge == "ball-keys" else "pipe.ball_keys.") for k in keys)
    assert any(s.startswith("materials.tube.normal.stiffness") for s in differ)


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("shared") / "study"
    overrides = ("drive.ramp=0.05", "load.ramp=0.05")
    result = sensitivity(None, out, parameters=["fatigue.neck_scf"], overrides=overrides, duration=0.15, workers=2,
                         progress=False, plots=False)  # fmt: skip
    return out, overrides, result


def test_a_shared_case_holds_what_running_it_gives(study) -> None:
    out, overrides, result = study
    summary = result.sweep.summary.to_pylist()
    assert [r["run_of"] for r in summary] == [0, 0, 0, 3], "low and high share the base's run; the check runs"
    assert result.sweep.shared == 2
    for row in summary[1:3]:
        scf = row["fatigue.neck_scf"]
        scene = default_scene([*overrides, "simulation.duration=0.15", f"fatigue.neck_scf={scf!r}",
                               'record.tables=["links","hinges","keys","drive","summary","wear","bodies","contacts","pairs"]'])  # fmt: skip
        alone = DRILL_PIPE_SENSITIVITY(ballcage.simulate(scene, progress=False))
        for name, value in alone.items():
            assert row[name] == value, (scf, name)
        # No table of its own: it reads the base's, with its own scene.
        assert not (out / "runs" / "links" / partition_name(row["case"])).exists()
        assert read_case_run(out / "runs", row["case"]).scene.value("fatigue.neck_scf") == scf
    base, low, high = (r["fatigue_life_min_h"] for r in summary[:3])
    # K_t multiplies the section's stresses: the life falls as it grows (Basquin–Goodman).
    assert low > base > high
    # The lives read every frame's contacts, which the study does not keep.
    assert not (out / "runs" / "contacts").exists() and base is not None


def test_a_lost_record_of_a_shared_case_is_computed_again(study) -> None:
    out, overrides, first = study
    record_path(out / "runs", partition_name(2)).unlink()
    again = sensitivity(None, out, parameters=["fatigue.neck_scf"], overrides=overrides, duration=0.15, workers=2,
                        progress=False, plots=False)  # fmt: skip
    # Its run (the base) runs again with it; the check stays finished.
    assert (again.sweep.ran, again.sweep.shared, again.sweep.skipped) == (3, 2, 1)
    keep = [c for c in first.sweep.summary.column_names if "wall_time" not in c]
    assert again.sweep.summary.select(keep).equals(first.sweep.summary.select(keep))


def test_a_study_whose_contacts_would_not_fit_its_memory_budget_runs_without_the_lives(tmp_path) -> None:
    # 5 MB holds the study's own tables for 0.15 s but not every frame's contacts (about 16 MB).
    overrides = ("drive.ramp=0.05", "load.ramp=0.05", "record.max_bytes=5000000",
                 'record.tables=["links", "hinges", "keys", "drive", "summary", "wear"]')
    result = sensitivity(None, tmp_path / "study", parameters=["fatigue.neck_scf"], overrides=overrides,
                         duration=0.15, workers=1, progress=False, plots=False, verify=False)  # fmt: skip
    rows = result.sweep.summary.to_pylist()
    assert [r["status"] for r in rows] == ["ok"] * 3
    assert all(r["fatigue_life_min_h"] is None and r["wear_hours_min_h"] is None for r in rows)
    assert all(r["tube_normal_mean_all_n"] > 0.0 for r in rows)
