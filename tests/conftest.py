"""Shared fixtures: example scene paths and small scenes built in Python."""

from __future__ import annotations

from pathlib import Path

import pytest

import ballcage

REPO = Path(__file__).resolve().parent.parent
SCENES = REPO / "examples" / "scenes"


@pytest.fixture
def ball_drop_path() -> Path:
    """examples/scenes/ball_drop.toml: 1 kg ball, r = 5 cm, Hertz K = 1e8, 0.2 s."""
    return SCENES / "ball_drop.toml"


@pytest.fixture
def two_balls_path() -> Path:
    """examples/scenes/two_balls.toml: head-on collision, Hunt–Crossley, no gravity."""
    return SCENES / "two_balls.toml"


def free_fall_builder(*, z0: float = 10.0, duration: float = 1.0, dt: float = 1e-3) -> ballcage.SceneBuilder:
    """A single ball falling with no contacts, recorded every 10 steps."""
    return (
        ballcage.SceneBuilder("free fall")
        .simulation(duration=duration, dt=dt, output_interval=10 * dt, integrator="rk4")
        .gravity([0.0, 0.0, -9.81])
        .body("ball", shape={"type": "ball", "radius": 0.05}, mass=2.0, position=[0.0, 0.0, z0])
        .record(tables=["bodies"])
    )


@pytest.fixture
def free_fall() -> ballcage.SceneBuilder:
    return free_fall_builder()
