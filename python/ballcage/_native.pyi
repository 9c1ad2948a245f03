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
    "SCENE_KINDS",
    "Error",
    "SceneError",
    "SimulationError",
    "InputError",
    "InternalError",
    "Scene",
    "Simulation",
    "default_scene_toml",
    "proposals",
    "integrator_facts",
    "table_schema",
    "whole_multiple",
    "longest_link",
    "tightest_radius_for_link",
    "largest_link_diameter",
    "tightest_radius_for_bend",
]

#: Every table name `TABLE_NAMES` holds, in its order (tests/test_units.py keeps the two equal).
_TableName = Literal["bodies", "contacts", "energy", "summary", "links", "hinges", "keys", "drive", "pairs", "wear"]

__version__: str
#: Cargo profile the extension was built with; "debug" runs ~10x slower.
BUILD_PROFILE: Literal["release", "debug"]
#: Every output table name, in the order `ballcage schema` prints them.
TABLE_NAMES: list[str]
#: Every integrator name `simulation.integrator` accepts, explicit ones first.
INTEGRATORS: list[str]
#: Every scene kind (the `kind` key of a scene document).
SCENE_KINDS: list[str]

class Error(Exception):
    """Base class of every error ballcage raises: ``except ballcage.Error`` catches them all."""

class SceneError(Error, ValueError):
    """A scene that cannot be read or validated.

    ``str(e)`` reads ``scene field `bodies[1].mass` = -2: must be positive``;
    an error of the text as a whole (``path`` empty) is its reason alone,
    ``TOML syntax error at line 2, column 7: …``.
    """

    #: Dotted path of the offending field, e.g. ``"bodies[1].mass"``; empty for a TOML syntax error.
    path: str
    #: The offending value as text; empty when the field is missing.
    value: str
    #: Why the value is rejected.
    reason: str
    #: Every error found in the same pass as ``(path, value, reason)``, the first being the one above;
    #: ``str(e)`` lists them all, separated by ``"; "``.
    errors: list[tuple[str, str, str]]

class SimulationError(Error, RuntimeError):
    """A run that had to stop because the state stopped being physical."""

class InputError(Error, ValueError, TypeError):
    """An argument of a ballcage function that is out of range or of the wrong type; the message names it."""

class InternalError(Error, RuntimeError):
    """A bug in ballcage: a Rust panic, caught and reported with where it happened."""

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

    def engine_digest(self) -> str:
        """A digest (hex) of everything a run of the scene computes from (its expansion, time stepping, recording,
        start and each pair's Hertz and wear model): two scenes with the same digest record bitwise the same tables,
        so a sweep runs them once; what they differ in enters only what is computed from the tables afterwards
        (``fatigue.*``) or nothing the scene builds (``pipe.ideal_cv.*`` with ball-key hinges)."""

    def to_toml(self, *, units: bool = False) -> str:
        """The resolved scene as TOML, with every default written out.

        With `units`, each line that sets a number ends in a comment naming its
        unit (``pitch = 0.2  # m``; contact laws in their own ``units``, e.g.
        ``# N/mm^2.2``), and each PROPOSAL (a value the paper does not give,
        `proposals`) follows a comment line with its plausible range and source
        (``# PROPOSAL, 17.5–21 mm: not in the paper``); the text parses to the
        same values.
        """

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
    def integrator(
        self,
    ) -> Literal["symplectic-euler", "rk4", "linearly-implicit-euler", "sdirk2", "esdirk32", "trbdf2"]: ...
    @property
    def table_names(self) -> list[str]:
        """Tables the scene records, e.g. ``["bodies", "contacts"]``."""

    @property
    def kind(self) -> Literal["generic", "drill-pipe"]:
        """The scene kind: a generic scene of bodies and pairs, or a drill pipe expanded into one."""

    @property
    def integrated_bodies(self) -> list[str]:
        """Names of the bodies the integrator moves (motion ``dynamic``, ``spin`` or ``spin-slide``), in body order; a drill pipe's expanded ones."""

    def unit(self, key: str) -> str:
        """The unit of the field at a dotted key, as ``to_toml(units=True)`` prints it.

        E.g. ``"m"`` for ``"borehole.curvature_radius"``, ``"rpm"`` for ``"drive.speed_rpm"``;
        ``"-"`` for a pure number and ``""`` for text, booleans and tables. Keys as in
        `value` (``"bodies[1].mass"`` or ``"bodies.1.mass"``; an element of an array of
        numbers answers as its array). A contact law's field answers in the law's own
        ``units``: ``"N/mm^2.2"`` for the paper's tube law stiffness. From the engine's one
        table of field units. Raises `InputError` naming the key when the scene has no
        such field.
        """

    def meaning(self, key: str) -> str:
        """One line on what the field at a dotted key is (keys as in `unit`). Raises `InputError` naming an unknown key."""

    def scale_from(self, key: str, units: Literal["SI", "N-mm-s"]) -> float:
        """The factor that turns a value of the contact-law field `key`, written in `units`, into the
        law's own units (those `unit` names): ``1000**n`` for a stiffness K [N/mm^n] of a law written
        in SI, ``1.0`` when the units are the law's own.

        Raises `InputError` for a key that is not a number of a contact law, or other `units`.
        """

    def value(self, key: str) -> Any:
        """The resolved value at a dotted key of the scene document, e.g. ``"pipe.ball_keys.ball_mass"``.

        Same keys as ``--set`` overrides (every default filled in); tables come
        back as dicts, arrays as lists. Raises `SceneError` naming the key when
        it does not exist.
        """

    def tightest_radius(self) -> float:
        """The tightest guide-tube curvature radius [m] this drill pipe's hinge allows.

        Whichever binds first of the articulation limit, R = p / (2 sin(β_max / 2)),
        and the paper's eq. (9) for a rigid link in the tube. Raises `SceneError`
        (path ``kind``) for a generic scene.
        """

    def articulation_limit_deg(self) -> float | None:
        """The bend [deg] at which the drill pipe's hinges bind (where the head's neck meets
        the seat's mouth); ``None`` when nothing limits the bend. Raises `SceneError`
        (path ``kind``) for a generic scene.
        """

    def centreline(self, count: int) -> dict[str, Any]:
        """`count` points along the drill pipe's tube centreline, extended straight past the arc.

        Keys ``"point"`` [m] and ``"tangent"`` (unit), world frame, and
        ``"outward"`` (unit: in the bend plane, toward the outer wall of the
        bend), each a list of ``[x, y, z]``; ``"s"`` [m] the arc length of each
        point, a list of floats. Raises `SceneError` for a generic scene.
        """

    def placed_chain(self) -> dict[str, Any]:
        """The drill pipe's chain as placed at t = 0 (docs/model.md §4, Option A).

        Keys ``"hinges"``: hinge centres 0 … n [m], and ``"axes"``: unit body axes
        in chain order (upper connector, links 1 … n, lower connector), world
        frame, each a list of ``[x, y, z]``; ``"masses"``: those bodies' masses
        [kg] as built (the ideal-CV links carry their hinges' cage and keys).
        Raises `SceneError` for a generic scene.
        """

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

        Raises `SimulationError` when the run diverges, `InputError` for a
        non-finite `t_end` or a finished simulation, and `InternalError` for a
        bug (a Rust panic), after which the simulation is dropped.
        """

    def finish(self) -> dict[str, pa.Table]:
        """One table per recorded table name. Callable once."""

def table_schema(name: _TableName | str) -> pa.Schema:
    """The Arrow schema of an output table; each field carries ``unit`` and ``description`` metadata.

    Raises `InputError` for a name not in `TABLE_NAMES`.
    """

def integrator_facts() -> dict[str, dict[str, Any]]:
    """Per integrator name, every one (the adaptive pairs ``esdirk32`` and ``trbdf2`` too, which `INTEGRATORS`
    leaves out): ``{"implicit": bool, "order": int, "newton_stages": int | None, "description": str}``.

    Implicit integrators solve a linear system per step; explicit ones must
    resolve the stiffest contact's period. ``newton_stages``: the implicit
    stages a step solves by Newton iterations (``None`` for the others).
    """

def whole_multiple(interval: float, step: float) -> int | None:
    """``interval / step`` when it is a whole number ≥ 1 within the engine's tolerance, else ``None``.

    The same test the scene validator applies to ``simulation.output_interval``.
    """

def default_scene_toml() -> str:
    """The embedded default scene (the paper's drill pipe, ``kind = "drill-pipe"``) as TOML, every default written out."""

def proposals(kind: Literal["generic", "drill-pipe"] | None = None) -> list[dict[str, Any]]:
    """The registry of unstated parameters (PROPOSAL values), one dict per entry; `ballcage.proposals` makes
    it a table.

    Keys ``key``, ``scene_kind``, ``default``, ``low``, ``high`` (floats, in ``unit``), ``unit``, ``source``
    (``"invented"``, ``"paper-reading"`` or ``"handbook"``), ``reference``, ``meaning`` and ``range_reason``.
    `kind` keeps one scene kind's entries. Raises `InputError` for another `kind`.
    """

def longest_link(curvature_radius: float, tube_inner_diameter: float, link_outer_diameter: float) -> float:
    """The paper's eq. (9): the longest rigid link [m] of outer diameter `link_outer_diameter` [m] that fits
    a tube of inner diameter `tube_inner_diameter` [m] bent to centreline radius `curvature_radius` [m],
    L = 2·√(2(D − 2r)(R + r)), r = d/2. Use `ballcage.sizing` (same names, argument checks).
    """

def tightest_radius_for_link(link_length: float, tube_inner_diameter: float, link_outer_diameter: float) -> float:
    """Eq. (9) solved for R: the tightest centreline radius [m] a rigid link `link_length` [m] long fits,
    R = (L/2)² / (2(D − 2r)) − r; ``inf`` when the link does not fit the straight tube.
    """

def largest_link_diameter(link_length: float, curvature_radius: float, tube_inner_diameter: float) -> float | None:
    """Eq. (9) solved for d: the largest outer diameter [m] of a rigid link `link_length` [m] long that fits,
    d = 2r = (D − 2R + √((2R + D)² − L²)) / 2; ``None`` when no link that long fits, L > 2·√(2RD).
    """

def tightest_radius_for_bend(pitch: float, bend_limit: float) -> float:
    """The tightest centreline radius [m] at which hinges `pitch` [m] apart bend by `bend_limit` [rad]:
    R = p / (2 sin(β / 2)).
    """
