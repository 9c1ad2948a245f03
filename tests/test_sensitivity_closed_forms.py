"""`ballcage sensitivity` against closed forms (issue 27, item 5): a resting ball's Hertz depth, Morris elementary
effects of a function with an interaction, and the same study run locally and on a real Dask ``LocalCluster``.

The resting ball: a ball of mass m on a fixed half-space under the Hertz
spring F = K δ^1.5 rests where K δ^1.5 = m g, at

    δ = (m g / K)^(2/3),   so   d ln δ / d ln K = −2/3   and   d ln δ / d ln m = +2/3.

The contact law is Hunt–Crossley with exponent 1.5: the Hertz spring, with
damping proportional to K δ^1.5 · δ̇, which vanishes at rest, so the ball
settles (the undamped ``hertz`` law would oscillate about δ for ever). It
starts touching the plane at rest and has settled to a relative 2e-10 of δ
after 0.4 s; the depth is ``depth_peak[ground/ball]`` [m], the pair's largest
penetration over the summary window, the last 0.1 s.
"""

from __future__ import annotations

import math
from pathlib import Path

import pyarrow as pa
import pytest

from ballcage.studies.sensitivity_design import problem
from ballcage.studies.sensitivity_effects import morris_indices
from ballcage.studies.sensitivity_parameters import ParameterRange
from ballcage.studies.sensitivity_run import Sensitivity, sensitivity
from ballcage.studies.sweep_summary import WALL_TIME_COLUMNS

G, M, K = 9.81, 1.0, 1e8  # m/s², kg, N/m^1.5
STIFFNESS, MASS = "contacts[0].normal.stiffness", "bodies[1].mass"
RANGES = {STIFFNESS: (5e7, 2e8), MASS: (0.5, 2.0)}  # N/m^1.5, kg: each end a factor 2 from the base
DEPTH, FORCE = "depth_peak[ground/ball]", "normal_peak[ground/ball]"
#: Relative tolerance of the depths, forces and slopes against their closed forms: measured within 2e-10 (the
#: depths 5e-11 to 1.9e-10 off, the slopes ±2/3 to 1.0e-10); the effects it must resolve are −37 % and +59 %.
TOLERANCE = 1e-8
RESTING_BALL = f"""
name = "resting ball"

[simulation]
duration = 0.5          # s
dt = 5e-5               # s
output_interval = 1e-3  # s
integrator = "rk4"

[world]
gravity = [0.0, 0.0, -{G}]

[record]
summary_window = [0.4, 0.5]  # s: after it has settled

[[bodies]]
name = "ground"
motion = "fixed"
shape = {{ type = "half-space", normal = [0.0, 0.0, 1.0] }}

[[bodies]]
name = "ball"
shape = {{ type = "ball", radius = 0.05 }}
mass = {M}
position = [0.0, 0.0, 0.05]  # m: touching the plane

[[contacts]]
bodies = ["ground", "ball"]
normal = {{ law = "hunt-crossley", stiffness = {K}, exponent = 1.5, restitution = 0.3 }}
"""


def _rest_depth(m: float, k: float) -> float:
    return (m * G / k) ** (2.0 / 3.0)


def _study(out: Path, **kwargs) -> Sensitivity:
    scene = out.parent / "resting_ball.toml"
    scene.write_text(RESTING_BALL, encoding="utf-8")
    options = {"parameters": RANGES, "workers": 2, "plots": False, "progress": False}
    return sensitivity(scene, out, **(options | kwargs))


def _rows(table: pa.Table) -> dict[tuple[str, str], dict]:
    return {(r["parameter"], r["quantity"]): r for r in table.to_pylist()}


@pytest.fixture(scope="module")
def local(tmp_path_factory: pytest.TempPathFactory) -> Sensitivity:
    return _study(tmp_path_factory.mktemp("local") / "study")


def test_resting_depth_moves_as_the_derivative_of_the_hertz_rest_depth(local: Sensitivity) -> None:
    rows = _rows(local.table)
    base = rows[(STIFFNESS, DEPTH)]
    assert base["unit"] == "m" and base["parameter_unit"] == "N/m^1.5"
    assert base["base"] == pytest.approx(_rest_depth(M, K), rel=TOLERANCE)
    measured = {}
    for key, slope in ((STIFFNESS, -2.0 / 3.0), (MASS, 2.0 / 3.0)):
        row = rows[(key, DEPTH)]
        low, high = RANGES[key]
        m_low, k_low = (low, K) if key == MASS else (M, low)
        m_high, k_high = (high, K) if key == MASS else (M, high)
        assert row["value_low"] == pytest.approx(_rest_depth(m_low, k_low), rel=TOLERANCE), key
        assert row["value_high"] == pytest.approx(_rest_depth(m_high, k_high), rel=TOLERANCE), key
        # d ln δ / d ln p over the range, and the change in % the table gives at the high end
        measured[key] = math.log(row["value_high"] / row["value_low"]) / math.log(high / low)
        assert measured[key] == pytest.approx(slope, abs=TOLERANCE), key
        assert row["change_high_pct"] == pytest.approx(100 * (2.0**slope - 1), abs=100 * TOLERANCE), key
        # the effect (|δ(high) − δ(base)| or |δ(low) − δ(base)|) is 37–59 % of δ: far above the tolerance and the error
        assert row["effect"] > 0.3 * row["base"] and row["rank"] in (1, 2), key
        assert row["numerical_error"] < 1e-3 * row["effect"] and row["below_error"] is False, key
    # δ depends on m/K alone: halving K is doubling m, so both parameters have the same effect
    assert rows[(STIFFNESS, DEPTH)]["value_low"] == pytest.approx(rows[(MASS, DEPTH)]["value_high"], rel=TOLERANCE)
    assert rows[(STIFFNESS, DEPTH)]["effect"] == pytest.approx(rows[(MASS, DEPTH)]["effect"], rel=TOLERANCE)
    print(f"d ln(depth)/d ln(K) = {measured[STIFFNESS]:.9f}, d ln(depth)/d ln(m) = {measured[MASS]:.9f}")


def test_resting_force_is_the_weight_whatever_the_stiffness(local: Sensitivity) -> None:
    rows = _rows(local.table)
    force = rows[(MASS, FORCE)]
    assert force["unit"] == "N" and force["base"] == pytest.approx(M * G, rel=TOLERANCE)
    assert force["value_low"] == pytest.approx(0.5 * G, rel=TOLERANCE)  # F = m g
    assert force["value_high"] == pytest.approx(2.0 * G, rel=TOLERANCE)
    stiff = rows[(STIFFNESS, FORCE)]  # the peak over the settled window: m g at any K
    assert abs(stiff["value_low"] - M * G) < TOLERANCE * M * G and abs(stiff["value_high"] - M * G) < TOLERANCE * M * G
    assert stiff["effect"] < 1e-4 * force["effect"]
    assert local.case_timeout_s is None  # a scene of bodies has no estimate before its base run: no time limit


# --------------------------------------------------------------------------- Morris


def test_morris_elementary_effects_of_a_function_with_an_interaction_match_the_closed_form() -> None:
    """f = a·x1 + b·x2·x3: the elementary effect of x1 is a·R1 on every step; of x2, b·R2·x3 at the step's x3; of
    x3, b·R3·x2 (R the ranges, SALib's effects being per whole range). mu, mu_star and sigma (ddof = 1) of those."""
    pytest.importorskip("SALib")
    from SALib.sample.morris import sample

    keys = ["x1", "x2", "x3"]
    bounds = [(0.0, 2.0), (-1.0, 3.0), (1.0, 5.0)]
    a, b, levels, trajectories = 1.5, -0.75, 4, 6
    ranges = [ParameterRange(k, lo, hi, (lo + hi) / 2, "", "given") for k, (lo, hi) in zip(keys, bounds, strict=True)]
    x = sample(problem(ranges), trajectories, num_levels=levels, seed=7)  # the study's own SALib problem
    y = [a * x1 + b * x2 * x3 for x1, x2, x3 in x]
    indices = morris_indices(ranges, x.tolist(), y, levels=levels, seed=7)

    span = [hi - lo for lo, hi in bounds]
    effects: dict[int, list[float]] = {0: [], 1: [], 2: []}
    for t in range(trajectories):
        path = x[t * 4:(t + 1) * 4]
        for before, after in zip(path[:-1], path[1:], strict=True):
            (k,) = [i for i in range(3) if before[i] != after[i]]  # one variable moves per step
            derivative = [a, b * before[2], b * before[1]][k]  # ∂f/∂x_k, constant along the step
            effects[k].append(derivative * span[k])
    assert all(len(e) == trajectories for e in effects.values())
    assert len(set(effects[1])) > 1 and len(set(effects[2])) > 1  # the interaction: effects vary between trajectories
    for k, key in enumerate(keys):
        mu_star, mu, sigma, _ = indices[key]
        e = effects[k]
        mean = sum(e) / len(e)
        std = math.sqrt(sum((v - mean) ** 2 for v in e) / (len(e) - 1))
        assert mu == pytest.approx(mean, rel=1e-12, abs=1e-12), key
        assert mu_star == pytest.approx(sum(abs(v) for v in e) / len(e), rel=1e-12), key
        assert sigma == pytest.approx(std, rel=1e-9, abs=1e-12), key
    assert indices["x1"][2] == pytest.approx(0.0, abs=1e-12)  # x1 enters linearly: no spread
    assert indices["x2"][2] > 0.1 and indices["x3"][2] > 0.1  # x2, x3 interact: a spread


# --------------------------------------------------------------------------- Dask


@pytest.mark.filterwarnings("ignore::DeprecationWarning", "ignore::ResourceWarning", "ignore::UserWarning")
def test_the_same_study_on_a_dask_local_cluster_gives_the_same_table(local: Sensitivity, tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        on_dask = _study(tmp_path / "study", workers=None, client=client)
    assert (on_dask.sweep.ran, on_dask.sweep.failed) == (6, 0)  # base, 2 x (low, high), the verification
    assert on_dask.table.equals(local.table)  # every value, to the bit (the metadata's date differs)
    assert on_dask.table.num_rows == local.table.num_rows == 2 * 7  # 2 parameters x (6 forces + the depth)

    def runs(study: Sensitivity) -> pa.Table:
        return study.sweep.summary.drop_columns(list(WALL_TIME_COLUMNS))

    assert runs(on_dask).equals(runs(local))
