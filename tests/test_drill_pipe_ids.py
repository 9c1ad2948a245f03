"""The drill pipe's tables identify parts by integer ids that join across tables.

The `pairs` table says what each contact pair is; joined to `contacts` on
`pair_id` it must give, per ball key and frame, the same race force the `keys`
table reports, and per link the tube force of `links`. No part name is parsed.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pytest

import ballcage
from ballcage.scene import default_scene

TABLES = '["pairs", "contacts", "keys", "links"]'


@pytest.fixture(scope="module")
def run() -> ballcage.Run:
    # 0.35 s: past the 0.3 s ramps, so keys and links carry load.
    scene = default_scene(["pipe.joints=2", "simulation.duration=0.35", f"record.tables={TABLES}"])
    return ballcage.simulate(scene)


def _last_frame(table: pa.Table) -> pa.Table:
    return table.filter(pc.equal(table["step"], pc.max(table["step"])))


def test_pairs_table_is_written_once_with_nullable_ids(run: ballcage.Run) -> None:
    pairs = run.tables["pairs"]
    assert pairs.num_rows == len(set(pairs["pair_id"].to_pylist()))
    assert pairs.schema.field("link").nullable and pairs.schema.field("key").nullable
    features = pairs["feature"].cast(pa.string()).to_pylist()
    tube = [i for i, f in enumerate(features) if f == "tube"]
    assert len(tube) == 2
    assert pairs["link"].to_pylist()[tube[0]] == 1 and pairs["key"].to_pylist()[tube[0]] is None


def test_contacts_joined_to_pairs_give_the_keys_table_race_forces(run: ballcage.Run) -> None:
    contacts = _last_frame(run.tables["contacts"]).join(run.tables["pairs"].drop(["pair"]), "pair_id")
    inner = contacts.filter(pc.equal(contacts["feature"].cast(pa.string()), "inner-race"))
    grouped = inner.group_by(["hinge", "key"]).aggregate([("normal_force", "sum")])
    keys = _last_frame(run.tables["keys"])
    expected = dict(zip(zip(keys["hinge"].to_pylist(), keys["key"].to_pylist()), keys["inner_normal"].to_pylist(), strict=True))
    got = dict(
        zip(zip(grouped["hinge"].to_pylist(), grouped["key"].to_pylist()), grouped["normal_force_sum"].to_pylist(), strict=True)
    )
    loaded = [hk for hk, f in expected.items() if f > 100.0]
    assert loaded, "no key carries load at the last frame: the check would be empty"
    for hk in loaded:
        assert got[hk] == pytest.approx(expected[hk], rel=1e-12)


def test_contacts_joined_to_pairs_give_the_links_table_tube_forces(run: ballcage.Run) -> None:
    contacts = _last_frame(run.tables["contacts"]).join(run.tables["pairs"].drop(["pair"]), "pair_id")
    tube = contacts.filter(pc.equal(contacts["feature"].cast(pa.string()), "tube"))
    grouped = tube.group_by("link").aggregate([("normal_force", "sum")])
    got = dict(zip(grouped["link"].to_pylist(), grouped["normal_force_sum"].to_pylist(), strict=True))
    links = _last_frame(run.tables["links"])
    for link, force in zip(links["link"].to_pylist(), links["tube_normal"].to_numpy(), strict=True):
        assert got.get(link, 0.0) == pytest.approx(float(force), rel=1e-12, abs=1e-9)
    assert np.any(links["tube_normal"].to_numpy() > 0.0), "no link touches the tube: the check would be empty"
