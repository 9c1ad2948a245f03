"""What the stability study varies: `Parameter`, the drill pipe's built-in ones and the cheap probe scene."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from ballcage import _native
from ballcage._native import InputError
from ballcage.scene import SceneSource, default_scene
from ballcage.studies.common import resolve, toml_value

__all__ = ["PARAMETER_NAMES", "Parameter", "drill_pipe_parameters", "probe_scene", "tightest_radius"]


@dataclass(frozen=True)
class Parameter:
    """A scene parameter a stability study varies: every override key in `keys` is set to each of `values`."""

    name: str
    keys: tuple[str, ...]
    values: tuple[float, ...]
    unit: str
    description: str = ""


#: Built-in drill-pipe parameters, in the order they are studied.
PARAMETER_NAMES: tuple[str, ...] = ("stiffness", "speed", "curvature_radius", "key_mass", "damping")
#: Range of the built-in parameters; the contact law's in the paper's N-mm-s units, set in the law's own
#: units (`ballcage.Scene.scale_from`).
STIFFNESS_RANGE = (1e3, 1e7)  # N/mm^n
SPEED_RANGE = (30.0, 600.0)  # rpm
LARGEST_RADIUS = 5.0  # m
KEY_MASS_FACTORS = (0.25, 4.0)  # × the scene's key mass
DAMPING_RANGE = (0.1, 100.0)  # N·s/mm, plus zero


def tightest_radius(scene: SceneSource | None = None) -> float:
    """The tightest tube curvature radius [m] the hinge allows, whichever binds first of:

    * the articulation limit: on an arc of radius R, links of pitch p bend by
      2·asin(p / 2R) at each joint, which the head's neck meeting the cage rim
      (``pipe.neck_radius``, docs/model.md §3) bounds: R = p / (2 sin(limit / 2))
      — 0.800 m for the paper's 200 mm pitch and the 14.36° limit;
    * the paper's eq. (9), the longest rigid link of radius r that fits the
      tube (diameter D): L = 2·√(2(D − 2r)(R + r)), so R = (p/2)² / (2(D − 2r)) − r
      — 0.124 m for the paper's 86 mm links in the 116 mm tube.

    The articulation limit binds first for the paper's pipe. `scene`: anything
    `ballcage.load_scene` takes; ``None`` is the embedded paper scene
    (`ballcage.Scene.tightest_radius`). Raises `ballcage.SceneError` (path
    ``kind``) for a generic scene.
    """
    return resolve(scene, ()).tightest_radius()


def drill_pipe_parameters(scene: SceneSource | None = None, values_per_parameter: int = 5) -> dict[str, Parameter]:
    """The built-in parameters (`PARAMETER_NAMES`) for a drill-pipe scene, `values_per_parameter` values each.

    - ``stiffness``: K of the internal contacts (keys on head and seat races,
      cage windows, cage on head and seat: ``materials.internal.normal.stiffness``),
      1e3–1e7 N/mm^n, log-spaced;
    - ``speed``: ``drive.speed_rpm``, 30–600 rpm, log-spaced;
    - ``curvature_radius``: ``borehole.curvature_radius`` from `tightest_radius` to 5 m, log-spaced;
    - ``key_mass``: ``pipe.ball_keys.ball_mass``, 1/4 to 4 × the scene's, log-spaced;
    - ``damping``: ``materials.internal.normal.damping``, zero and 0.1–100 N·s/mm log-spaced.
    """
    if values_per_parameter < 2:
        raise InputError(f"values_per_parameter = {values_per_parameter}: must be at least 2")
    resolved = resolve(scene, ())
    if resolved.kind != "drill-pipe":
        raise InputError(f"scene kind = {resolved.kind!r}: the built-in stability parameters need a drill-pipe scene")
    n = values_per_parameter
    k_key, c_key = "materials.internal.normal.stiffness", "materials.internal.normal.damping"
    (k_scale, k_unit), (c_scale, c_unit) = _in_law_units(resolved, k_key), _in_law_units(resolved, c_key)
    mass = float(resolved.value("pipe.ball_keys.ball_mass"))

    def geom(lo: float, hi: float, count: int) -> tuple[float, ...]:
        return tuple(float(v) for v in np.geomspace(lo, hi, count))

    return {
        "stiffness": Parameter(
            "stiffness",
            (k_key,),
            tuple(v * k_scale for v in geom(*STIFFNESS_RANGE, n)),
            k_unit,
            "K of the internal (key, cage) contacts",
        ),
        "speed": Parameter(
            "speed", ("drive.speed_rpm",), geom(*SPEED_RANGE, n), resolved.unit("drive.speed_rpm"), "drive speed"
        ),
        "curvature_radius": Parameter(
            "curvature_radius",
            ("borehole.curvature_radius",),
            geom(tightest_radius(resolved), LARGEST_RADIUS, n),
            resolved.unit("borehole.curvature_radius"),
            "guide tube curvature radius, from the tightest the hinge allows",
        ),
        "key_mass": Parameter(
            "key_mass",
            ("pipe.ball_keys.ball_mass",),
            geom(mass * KEY_MASS_FACTORS[0], mass * KEY_MASS_FACTORS[1], n),
            resolved.unit("pipe.ball_keys.ball_mass"),
            "ball key mass",
        ),
        "damping": Parameter(
            "damping",
            (c_key,),
            (0.0, *(v * c_scale for v in geom(*DAMPING_RANGE, n - 1))),
            c_unit,
            "damping of the internal contacts (IMPACT c_max)",
        ),
    }


def _in_law_units(scene: _native.Scene, key: str) -> tuple[float, str]:
    """The factor from the paper's N-mm-s units to the units `scene`'s contact law writes `key` in, and
    that unit, both from the engine; ``(1.0, "")`` when the law has no such field (setting it fails
    then, naming it)."""
    try:
        return scene.scale_from(key, "N-mm-s"), scene.unit(key)
    except InputError:
        return 1.0, ""


#: The default probe scene: the paper's drill pipe, shortened (see `probe_scene`).
PROBE_JOINTS = 2
PROBE_DURATION = 0.03  # s
PROBE_RAMP = 0.01  # s


def probe_scene(overrides: Iterable[str] = (), duration: float | None = None) -> _native.Scene:
    """The cheap drill-pipe scene `stability` probes by default.

    The paper's scene with ``pipe.joints = 2``, ``simulation.duration = 0.03``
    s and the drive and load ramped in over 0.01 s (instead of 0.3 s) so the
    keys carry the full 1.8 kN·m during the probe; then `overrides`, then
    `duration` [s] if given.
    """
    patches = [
        f"pipe.joints={PROBE_JOINTS}",
        f"simulation.duration={toml_value(PROBE_DURATION)}",
        f"drive.ramp={toml_value(PROBE_RAMP)}",
        f"load.ramp={toml_value(PROBE_RAMP)}",
        *overrides,
    ]
    if duration is not None:
        patches.append(f"simulation.duration={toml_value(duration)}")
    return default_scene(patches)


def assign(parameter: Parameter, value: float) -> list[str]:
    """The overrides that set every key of `parameter` to `value`."""
    return [f"{key}={toml_value(value)}" for key in parameter.keys]
