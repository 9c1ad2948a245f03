"""One scene, three ways in (TOML file, dict, SceneBuilder): bitwise identical runs."""

from __future__ import annotations

import tomllib

import pytest

import ballcage

SCENE_TOML = """
name = "spinning drop"

[simulation]
duration = 0.2
dt = 5e-5
output_interval = 1e-3
integrator = "rk4"

[world]
gravity = [0.0, 0.0, -9.81]

[record]
tables = ["bodies", "contacts", "energy"]

[[bodies]]
name = "ground"
motion = "fixed"
shape = { type = "half-space", normal = [0.0, 0.0, 1.0] }

[[bodies]]
name = "ball"
shape = { type = "ball", radius = 0.05 }
mass = 1.0
position = [0.0, 0.0, 0.1]
velocity = [0.2, 0.0, 0.0]

[[contacts]]
bodies = ["ground", "ball"]
normal = { law = "hunt-crossley", stiffness = 1e8, exponent = 1.5, restitution = 0.5 }
friction = { law = "adams", mu_static = 0.3, mu_dynamic = 0.1, v_static = 0.1, v_dynamic = 1.0 }

[[loads]]
type = "torque"
body = "ball"
axis = [0.0, 0.0, 1.0]
magnitude = 0.01
ramp = 0.05
"""


def built() -> ballcage.SceneBuilder:
    return (
        ballcage.SceneBuilder("spinning drop")
        .simulation(duration=0.2, dt=5e-5, output_interval=1e-3, integrator="rk4")
        .gravity([0.0, 0.0, -9.81])
        .record(tables=["bodies", "contacts", "energy"])
        .body("ground", motion="fixed", shape={"type": "half-space", "normal": [0.0, 0.0, 1.0]})
        .body(
            "ball",
            shape={"type": "ball", "radius": 0.05},
            mass=1.0,
            position=(0.0, 0.0, 0.1),
            velocity=[0.2, 0.0, 0.0],
        )
        .contact(
            "ground",
            "ball",
            normal={"law": "hunt-crossley", "stiffness": 1e8, "exponent": 1.5, "restitution": 0.5},
            friction={"law": "adams", "mu_static": 0.3, "mu_dynamic": 0.1, "v_static": 0.1, "v_dynamic": 1.0},
        )
        .torque("ball", [0.0, 0.0, 1.0], 0.01, ramp=0.05)
    )


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "spinning_drop.toml"
    path.write_text(SCENE_TOML, encoding="utf-8")
    return path


def test_toml_dict_and_builder_resolve_to_the_same_scene(scene_file):
    from_file = ballcage.load_scene(scene_file).to_toml()
    assert ballcage.load_scene(tomllib.loads(SCENE_TOML)).to_toml() == from_file
    assert ballcage.load_scene(built()).to_toml() == from_file
    assert ballcage.load_scene(built().to_dict()).to_toml() == from_file


def test_toml_dict_and_builder_give_bitwise_identical_tables(scene_file):
    reference = ballcage.simulate(scene_file)
    assert set(reference.tables) == {"bodies", "contacts", "energy"}
    assert reference.contacts.num_rows > 0  # the ball lands: the comparison covers contact rows too

    for source in (tomllib.loads(SCENE_TOML), built()):
        other = ballcage.simulate(source)
        assert set(other.tables) == set(reference.tables)
        for name, table in reference.tables.items():
            assert other.tables[name].schema.equals(table.schema, check_metadata=False), name
            assert other.tables[name].equals(table), name
        assert other.scene_toml == reference.scene_toml


def test_resolved_scene_round_trips(scene_file):
    resolved = ballcage.load_scene(scene_file).to_toml()
    assert ballcage.Scene.from_toml(resolved).to_toml() == resolved
    assert ballcage.load_scene(ballcage.load_scene(scene_file)).to_toml() == resolved


def test_duration_override_changes_the_frame_count(scene_file):
    full = ballcage.simulate(scene_file).bodies
    short = ballcage.simulate(scene_file, overrides=["simulation.duration=0.1"]).bodies
    # One recorded body ("ball"; fixed bodies are not recorded by default),
    # frames at 0, 1 ms, ..., duration.
    assert full.num_rows == round(0.2 / 1e-3) + 1
    assert short.num_rows == round(0.1 / 1e-3) + 1
    assert max(short["t"].to_pylist()) == pytest.approx(0.1, abs=1e-12)
    # The shorter run is a prefix of the longer one.
    assert short.equals(full.slice(0, short.num_rows))


def test_overrides_apply_to_every_source_alike(scene_file):
    sets = ["bodies.1.mass=2", "simulation.integrator=\"symplectic-euler\""]
    via_file = ballcage.load_scene(scene_file, sets)
    assert "symplectic-euler" == via_file.integrator
    assert ballcage.load_scene(built(), sets).to_toml() == via_file.to_toml()
    assert ballcage.load_scene(ballcage.load_scene(scene_file), sets).to_toml() == via_file.to_toml()
    assert tomllib.loads(via_file.to_toml())["bodies"][1]["mass"] == 2.0


def test_builder_to_dict_is_a_copy():
    builder = built()
    snapshot = builder.to_dict()
    snapshot["bodies"][1]["mass"] = -1.0
    assert builder.to_dict()["bodies"][1]["mass"] == 1.0


def test_overrides_must_be_a_list_not_a_string(scene_file):
    with pytest.raises(TypeError, match="list"):
        ballcage.load_scene(scene_file, "simulation.duration=0.1")


def test_missing_scene_file_names_the_path(tmp_path):
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(FileNotFoundError, match="nowhere.toml") as info:
        ballcage.load_scene(missing)
    assert info.value.filename == str(missing)
