"""The compiled core (Rust, PyO3). Private: use the names re-exported by `ballcage`.

Everything here is SI: lengths in m, times in s, forces in N.
"""

from collections.abc import Sequence
from typing import Any, Literal, Self, final

import pyarrow as pa

__all__ = [
    "__version__",
    "BUILD_PROFILE",
    "TABLE_NAMES",
    "INTEGRATORS",
    "SceneError",
    "SimulationError",
    "Scene",
    "Simulation",
    "default_scene_toml",
    "table_schema",
]

TableName = Literal["bodies", "contacts", "energy", "summary", "links", "hinges", "keys", "drive"]

__version__: str
#: Cargo profile the extension was built with; "debug" runs ~10x slower.
BUILD_PROFILE: Literal["release", "debug"]
#: Every output table name, in the order `ballcage schema` prints them.
TABLE_NAMES: list[str]
#: Every integrator name `simulation.integrator` accepts, explicit ones first.
INTEGRATORS: list[str]

class SceneError(ValueError):
    """A scene that cannot be read or validated.

    ``str(e)`` reads ``scene field `bodies[1].mass` = -2: must be positive``.
    """

    #: Dotted path of the offending field, e.g. ``"bodies[1].mass"``.
    path: str
    #: The offending value as text; empty when the field is missing.
    value: str
    #: Why the value is rejected.
    reason: str

class SimulationError(RuntimeError):
    """A run that had to stop because the state stopped being physical."""

@final
class Scene:
    """A validated scene. Immutable; build one per variation."""

    @staticmethod
    def from_toml(text: str, overrides: Sequence[str] = ...) -> Scene:
        """Parses TOML text, applies ``dotted.key=value`` overrides, validates.

        Raises `SceneError`.
        """

    @staticmethod
    def from_dict(obj: dict[str, Any], overrides: Sequence[str] = ...) -> Scene:
        """Same as `from_toml` for a dict of the same structure. Raises `SceneError`."""

    def to_toml(self) -> str:
        """The resolved scene as TOML, with every default written out."""

    @property
    def name(self) -> str: ...
    @property
    def duration(self) -> float:
        """Simulated duration [s]."""

    @property
    def dt(self) -> float:
        """Integrator step [s]."""

    @property
    def output_interval(self) -> float:
        """Interval between recorded frames [s]."""

    @property
    def integrator(self) -> Literal["rk4", "symplectic-euler", "linearly-implicit-euler"]: ...
    @property
    def table_names(self) -> list[str]:
        """Tables the scene records, e.g. ``["bodies", "contacts"]``."""

@final
class Simulation:
    """One run of a scene. Advance it, then `finish` it once."""

    def __new__(cls, scene: Scene) -> Self: ...
    @property
    def time(self) -> float:
        """Simulated time reached [s]."""

    @property
    def duration(self) -> float:
        """Scene duration [s]."""

    @property
    def steps(self) -> int:
        """Integrator steps taken."""

    def advance(self, t_end: float) -> None:
        """Steps (without the GIL) until `time` >= `t_end`, clamped to `duration`.

        Raises `SimulationError`.
        """

    def finish(self) -> dict[str, pa.Table]:
        """One table per recorded table name. Callable once."""

def table_schema(name: TableName | str) -> pa.Schema:
    """The Arrow schema of an output table; each field carries ``unit`` and ``description`` metadata.

    Raises `ValueError` for a name not in `TABLE_NAMES`.
    """

def default_scene_toml() -> str:
    """The embedded default scene (the paper's drill pipe, ``kind = "drill-pipe"``) as TOML, every default written out."""
