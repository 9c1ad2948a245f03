"""`ballcage view`: the chain turning in 3D, as an offline HTML page checked in a real headless Chromium, and as a GIF/MP4.

The browser test loads the page in Debian's ``chromium`` (software WebGL:
SwiftShader) with every host name unresolvable and a dead proxy, so that the
page can only draw if it fetches nothing. Chromium dumps the DOM after
plotly's first render, where the page's marker ``#ballcage-status`` states
how many link meshes plotly built and how many are in the WebGL scene, and
takes a screenshot, whose 3D scene (its box is in the marker) must be drawn:
not one flat colour, and holding the link colour scale's (viridis) colours.
A control page whose WebGL canvas is hidden must fail that same check.
Without chromium the browser tests are skipped with the reason;
scripts/test-all.sh installs it first.
"""

from __future__ import annotations

import colorsys
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.compute as pc
import pytest
from PIL import Image

import ballcage
from ballcage.scene import default_scene
from ballcage.view import chain_frames, read_run, write_view

JOINTS = 12
CHAIN = ["upper", *[f"link{k:02}" for k in range(1, JOINTS + 1)], "lower"]
#: Every ball key of the paper's pipe (hinges 0-12, six keys each; names.rs `names::key`).
KEYS = [f"h{h:02}.key{j}" for h in range(JOINTS + 1) for j in range(6)]
#: Browser window [px]; headless Chromium's viewport is shorter by its (invisible) window frame.
WINDOW = (1280, 800)
#: Virtual time [ms] the page gets to load its 5 MB and render before the dump and the screenshot.
BUDGET_MS = 30_000
CHROMIUM = next((p for p in map(shutil.which, ("chromium", "chromium-browser", "google-chrome")) if p), None)
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None,
    reason="no chromium on PATH: the browser test needs Debian's chromium (scripts/test-all.sh runs apt-get install chromium)",
)
#: Smallest share of the scene's pixels in the links' colours (about 2 % on the test page; 0 when the canvas is blank).
MIN_LINK_PIXELS = 0.003


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballcage", *args], capture_output=True, text=True, timeout=300)


def _simulate(out: Path, overrides: list[str]) -> Path:
    ballcage.simulate(default_scene(["simulation.duration=0.03", *overrides]), progress=False).write(out)
    return out


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    """A 30 ms run of the paper's scene recording the chain's and every key's pose, and the links table."""
    bodies = "record.bodies=" + json.dumps(CHAIN + KEYS)
    return _simulate(tmp_path_factory.mktemp("run"), [bodies, 'record.tables=["bodies", "links"]'])


@pytest.fixture(scope="module")
def page(run_dir: Path, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("view") / "chain.html"
    proc = _cli("view", str(run_dir), "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith(f"wrote {out}  (3D view, ")
    return out


def _chromium(url: str, screenshot: Path, profile: Path) -> dict[str, str]:
    """Loads `url` offline in headless Chromium; writes `screenshot` (PNG) and returns the page marker's attributes."""
    assert CHROMIUM is not None
    args = [
        CHROMIUM, "--headless", "--no-sandbox", "--disable-dev-shm-usage", "--no-first-run", "--disable-extensions",
        "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--hide-scrollbars",
        "--host-resolver-rules=MAP * ~NOTFOUND", "--proxy-server=127.0.0.1:9",  # no network: every fetch fails
        f"--window-size={WINDOW[0]},{WINDOW[1]}", f"--virtual-time-budget={BUDGET_MS}", f"--user-data-dir={profile}",
        f"--screenshot={screenshot}", "--dump-dom", url,
    ]  # fmt: skip
    proc = subprocess.run(args, capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stderr[-2000:]
    marker = re.search(r'<div id="ballcage-status"([^>]*)>', proc.stdout)
    assert marker is not None, "the page never wrote its marker: plotly did not render (stderr: " + proc.stderr[-800:] + ")"
    return dict(re.findall(r'(data-[\w-]+)="([^"]*)"', marker.group(1)))


def _scene_pixels(screenshot: Path, status: dict[str, str]) -> np.ndarray:
    """The screenshot's pixels inside the 3D scene's box (RGB in 0-1), a few pixels in from its edges."""
    left, top, right, bottom = (int(v) for v in status["data-scene-box"].split(","))
    rgb = np.asarray(Image.open(screenshot).convert("RGB"), dtype=float) / 255.0
    return rgb[top + 4 : bottom - 4, left + 4 : right - 4]


def _link_coloured(pixels: np.ndarray) -> np.ndarray:
    """Which pixels are in viridis' colours: saturated, not black, hue from its yellow (55°) to its purple (285°).

    The tube (pale blue, 10 % opaque), grid, white background, grey connectors and dark keys are all unsaturated.
    """
    flat = pixels.reshape(-1, 3)
    high, low = flat.max(axis=1), flat.min(axis=1)
    saturation = np.where(high > 0, (high - low) / np.maximum(high, 1e-9), 0.0)
    candidates = (saturation > 0.35) & (high > 0.12)
    hue = np.zeros(len(flat))
    for i in np.flatnonzero(candidates):
        hue[i] = 360.0 * colorsys.rgb_to_hsv(*flat[i])[0]
    return candidates & (hue >= 45.0) & (hue <= 300.0)


def _assert_drawn(pixels: np.ndarray) -> float:
    """Fails unless the scene is drawn: not one flat colour, and links in the colour scale's colours; returns their share."""
    assert pixels.size, "empty scene box"
    assert float(pixels.std()) > 0.03, "the 3D scene is one flat colour: nothing was drawn"
    share = float(_link_coloured(pixels).mean())
    assert share >= MIN_LINK_PIXELS, f"only {share:.2%} of the scene is in the links' colours: the links were not drawn"
    return share


@needs_chromium
def test_headless_chromium_draws_every_link_offline(page: Path, tmp_path: Path) -> None:
    status = _chromium(page.as_uri(), tmp_path / "view.png", tmp_path / "profile")

    assert status["data-webgl"] == "true", status
    assert status["data-link-meshes"] == str(JOINTS)
    assert status["data-drawn-link-meshes"] == str(JOINTS)  # each link's mesh is an object of the WebGL scene
    assert status["data-keys"] == str(len(KEYS))
    assert int(status["data-frames"]) == 31  # every 1 ms frame of the 30 ms run, ends included
    _assert_drawn(_scene_pixels(tmp_path / "view.png", status))


@needs_chromium
def test_a_page_whose_canvas_is_hidden_fails_the_drawing_check(page: Path, tmp_path: Path) -> None:
    """The control: plotly builds the same traces, but nothing reaches the screen, and the check must say so."""
    hidden = tmp_path / "hidden.html"
    text = page.read_text(encoding="utf-8")
    hidden.write_text(text.replace("</head>", "<style>.gl-container { visibility: hidden; }</style></head>", 1), encoding="utf-8")
    status = _chromium(hidden.as_uri(), tmp_path / "hidden.png", tmp_path / "profile")

    assert status["data-link-meshes"] == str(JOINTS)
    with pytest.raises(AssertionError, match="flat colour|links' colours"):
        _assert_drawn(_scene_pixels(tmp_path / "hidden.png", status))


@needs_chromium
def test_the_address_picks_the_frame_and_a_links_only_run_is_drawn(run_dir: Path, tmp_path: Path) -> None:
    links_only = _simulate(tmp_path / "run", ['record.tables=["links"]'])
    out = write_view(links_only, tmp_path / "links.html", frames=5)
    status = _chromium(out.as_uri() + "#t=0.02", tmp_path / "links.png", tmp_path / "profile")

    assert status["data-link-meshes"] == str(JOINTS) and status["data-drawn-link-meshes"] == str(JOINTS)
    assert status["data-frames"] == "5" and status["data-keys"] == "0"
    assert float(status["data-time"]) == pytest.approx(0.022, abs=1e-9)  # of 0, 0.007, 0.015, 0.022, 0.03 s
    _assert_drawn(_scene_pixels(tmp_path / "links.png", status))


def test_the_page_is_self_contained(page: Path) -> None:
    text = page.read_text(encoding="utf-8")

    assert re.search(r"<script[^>]*\ssrc=", text) is None  # every script is inline
    assert re.search(r"<link[^>]*\shref=", text) is None
    assert "plotly.js v" in text[:5000]  # the library itself, from the plotly package
    assert text.count('"meta":"link"') == JOINTS
    assert "tube force [N]" in text and "x [m]" in text
    assert '"label":"\\u25b6 play"' in text or "▶ play" in text
    assert 4e6 < page.stat().st_size < 8e6  # the 4.8 MB library and 31 frames of 14 bodies, 78 keys


def test_poses_from_bodies_match_the_links_table(run_dir: Path) -> None:
    """The body x axis is the link axis: the quaternions give eq. (4)'s angles, the positions the links' com."""
    run = read_run(run_dir)
    from_bodies = chain_frames(run)
    links_only = ballcage.Run({"links": run.tables["links"]}, run.scene_toml)
    from_links = chain_frames(links_only)

    assert from_bodies.source == "bodies" and from_links.source == "links"
    assert from_bodies.labels == ("upper connector", *[f"link {k}" for k in range(1, JOINTS + 1)], "lower connector")
    np.testing.assert_allclose(from_bodies.times, from_links.times)
    links = from_bodies.is_link
    np.testing.assert_allclose(from_bodies.axes[:, links], from_links.axes, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(from_bodies.sides, axis=-1), 1.0, atol=1e-9)
    np.testing.assert_allclose(np.sum(from_bodies.axes * from_bodies.sides, axis=-1), 0.0, atol=1e-9)
    np.testing.assert_allclose(from_bodies.tube_force[:, links], from_links.tube_force)
    # with the keys recorded, links are drawn a cage length shorter at each hinge, about the same centre
    np.testing.assert_allclose(from_bodies.centres[:, links], from_links.centres, atol=1e-9)
    assert from_bodies.lengths[1] == pytest.approx(0.2 - 0.04)
    assert from_bodies.keys is not None and from_bodies.keys.shape == (31, len(KEYS), 3)


def test_the_view_tells_the_bodies_apart_by_their_part_ids(run_dir: Path) -> None:
    """The bodies table says what each body is (part, link, hinge, key); the view reads those, not the names."""
    import pyarrow.parquet as pq

    bodies = pq.read_table(run_dir / "bodies.parquet")
    first = bodies.filter(pc.equal(bodies.column("step"), 0)).to_pylist()
    parts = {(r["part"], r["link"], r["hinge"], r["key"]) for r in first}
    assert {p for p in parts if p[0] == "link"} == {("link", k, None, None) for k in range(1, JOINTS + 1)}
    assert {p for p in parts if p[0] == "key"} == {("key", None, h, j) for h in range(JOINTS + 1) for j in range(6)}
    assert {p for p in parts if p[0] in ("upper", "lower")} == {("upper", None, None, None), ("lower", None, None, None)}
    assert len(first) == len(CHAIN) + len(KEYS)

    run = read_run(run_dir)
    assert "body" not in run.tables["bodies"].column_names  # names are not even read
    chain = chain_frames(run)
    assert chain.labels == ("upper connector", *[f"link {k}" for k in range(1, JOINTS + 1)], "lower connector")
    assert chain.keys is not None and chain.keys.shape[1] == len(KEYS)
    # keys in (hinge, key) order: key 0 of hinge 0 sits between the upper connector and link 1
    upper, link1 = chain.centres[0, 0], chain.centres[0, 1]
    key = chain.keys[0, 0]
    assert np.linalg.norm(key - (upper + link1) / 2) < np.linalg.norm(upper - link1)


def test_the_tube_follows_the_scene_centreline(run_dir: Path) -> None:
    chain = chain_frames(read_run(run_dir), max_frames=3)
    tube = chain.tube
    scene = read_run(run_dir).scene

    assert tube.inner_radius == pytest.approx(0.058)
    np.testing.assert_allclose(tube.points[0], [0.0, 0.0, 0.2])  # a connector length above the top hinge
    np.testing.assert_allclose(tube.points[1], scene.centreline(2)["point"][0])
    arc = tube.points[(tube.points[:, 2] < 0) & (tube.points[:, 0] < 1.5)]
    radius = 1.5  # the arc P(a) = (R(1 - cos a), 0, -R sin a) about (R, 0, 0)
    np.testing.assert_allclose(np.hypot(arc[:, 0] - radius, arc[:, 2]), radius, atol=1e-9)
    centres = chain.centres[:, chain.is_link].reshape(-1, 3)
    nearest = np.min(np.linalg.norm(centres[:, None, :] - tube.points[None, :, :], axis=-1), axis=1)
    assert nearest.max() < tube.inner_radius  # every link centre is inside the drawn tube


def test_gif_export_has_the_frames_asked_for(run_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "chain.gif"
    proc = _cli("view", str(run_dir), "--out", str(out), "--frames", "4", "--fps", "5")

    assert proc.returncode == 0, proc.stderr
    with Image.open(out) as gif:
        assert gif.format == "GIF" and gif.n_frames == 4 and gif.size == (960, 640)
        assert gif.info["duration"] == 200
    assert out.stat().st_size > 10_000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["chain.gif"]  # no temporary left behind


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="no ffmpeg on PATH (Debian: apt-get install ffmpeg)")
def test_mp4_export(run_dir: Path, tmp_path: Path) -> None:
    out = write_view(run_dir, tmp_path / "chain.mp4", frames=3)

    assert out.read_bytes()[4:8] == b"ftyp"  # an ISO media file
    assert out.stat().st_size > 1000


@pytest.mark.parametrize(
    ("args", "expect"),
    [
        (["{missing}", "--out", "{tmp}/a.html"], "no such directory"),
        (["{tmp}", "--out", "{tmp}/a.html"], "no scene.toml"),
        (["{drive}", "--out", "{tmp}/a.html"], "no link poses"),
        (["{run}", "--out", "{tmp}/a.png"], "'.png': the suffix picks the kind; write .html, .gif, .mp4"),
        (["{run}", "--out", "{tmp}/a.html", "--frames", "0"], "--frames 0: must be at least 1"),
        (["{run}", "--out", "{tmp}/a.html", "--fps", "-2"], "--fps -2: must be a positive number"),
        (["{run}", "--out", "{tmp}/a.html", "--scale", "60"], "--scale 60: must be from 1 to 50"),
        (["{run}", "--out", "{tmp}/a.html", "--scale", "0.5"], "--scale 0.5: must be from 1 to 50"),
        (["{run}", "--out", "{tmp}/a.html", "--wear"], "no wear_map.parquet"),
        (["{run}", "--out", "{tmp}/a.gif", "--wear"], "--wear: the wear colouring is drawn on the HTML page"),
    ],
)
def test_bad_input_exits_2_naming_it(args: list[str], expect: str, run_dir: Path, tmp_path: Path) -> None:
    drive = _simulate(tmp_path / "drive", ['record.tables=["drive"]'])
    names = {"missing": tmp_path / "missing", "tmp": tmp_path, "drive": drive, "run": run_dir}
    proc = _cli("view", *(a.format(**{k: str(v) for k, v in names.items()}) for a in args))

    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("ballcage: error: ")
    assert expect in proc.stderr
    assert not (tmp_path / "a.html").exists() and not (tmp_path / "a.png").exists()


def test_write_view_refuses_a_generic_scene(tmp_path: Path) -> None:
    scene = ballcage.SceneBuilder("drop").simulation(duration=0.01, dt=1e-3, output_interval=1e-3)
    scene = scene.body("ball", shape={"type": "ball", "radius": 0.05}, mass=1.0).record(tables=["bodies"])
    run = ballcage.simulate(scene, progress=False)

    with pytest.raises(ballcage.InputError, match="scene kind = 'generic'"):
        write_view(run, tmp_path / "chain.html")


@pytest.fixture(scope="module")
def worn_run(tmp_path_factory) -> Path:
    """0.12 s of the paper's scene by `ballcage run` (the links reach the wall at 0.08 s), its wear map in coarse
    cells (50 mm × 30°) so that the worn wall shows at the view's distance."""
    out = tmp_path_factory.mktemp("worn")
    sets = [
        "simulation.duration=0.12", "wear.map_cell_length=0.05", "wear.map_cell_angle_deg=30",
        'record.tables=["bodies", "contacts", "links", "wear"]',
    ]  # fmt: skip
    proc = _cli("run", "--out", str(out), "--quiet", *(a for s in sets for a in ("--set", s)))
    assert proc.returncode == 0, proc.stderr
    return out


def test_the_displacement_scale_multiplies_each_offset_from_the_centreline(worn_run: Path) -> None:
    from ballcage.view.scale import scaled

    chain = chain_frames(read_run(worn_run), 5)
    big = scaled(chain, 20.0)

    def ends(c):
        half = 0.5 * np.stack([c.lengths_at(f) for f in range(len(c.times))])[..., None] * c.axes
        return np.stack([c.centres - half, c.centres + half], axis=2)

    radius = 1.5  # the arc P(a) = (R(1 - cos a), 0, -R sin a) about (R, 0, 0): an end's exact offset is
    # (R - its distance from the arc's axis) in the bend plane and y across it

    def offset(points):
        return np.stack([radius - np.hypot(points[..., 0] - radius, points[..., 2]), points[..., 1]], axis=-1)

    on_arc = (ends(chain)[..., 2] < -0.01) & (ends(chain)[..., 0] < radius - 0.01)
    true = offset(ends(chain))[on_arc]
    assert np.abs(true).max() > 0.005  # the fold: links off the centreline by millimetres
    # to within the view's centreline samples (20 mm apart: 33 µm off the arc, 0.7 mm at x20)
    np.testing.assert_allclose(offset(ends(big))[on_arc], 20.0 * true, atol=1e-3)
    assert np.abs(offset(ends(big))[on_arc] - true).max() > 0.09  # and the 20 times is seen: 0.1 m and more
    # the chain stays connected: two bodies' ends at a hinge stay within 20 times their true distance
    def gap(c):
        return np.linalg.norm(ends(c)[:, 1:, 0] - ends(c)[:, :-1, 1], axis=-1)

    assert np.all(gap(big) <= 20.0 * gap(chain) + 1e-9)
    assert big.scale == 20.0 and scaled(chain, 1.0) is chain


def _worn_coloured(pixels: np.ndarray) -> np.ndarray:
    """Which pixels are in the wear scale's colours (orange to dark red): saturated, hue within 40° of red."""
    flat = pixels.reshape(-1, 3)
    high, low = flat.max(axis=1), flat.min(axis=1)
    saturation = np.where(high > 0, (high - low) / np.maximum(high, 1e-9), 0.0)
    hue = np.array([360.0 * colorsys.rgb_to_hsv(*rgb)[0] for rgb in flat])
    return (saturation > 0.45) & (high > 0.3) & ((hue <= 40.0) | (hue >= 340.0))


@needs_chromium
def test_chromium_draws_the_scaled_chain_and_the_worn_tube_wall(worn_run: Path, tmp_path: Path) -> None:
    """The same page at ×20 with and without --wear: the worn cells are in the WebGL scene and on the screen."""
    import pyarrow.parquet as pq

    pages = {}
    for name, extra in (("plain", []), ("worn", ["--wear"])):
        out = tmp_path / f"{name}.html"
        proc = _cli("view", str(worn_run), "--out", str(out), "--frames", "5", "--scale", "20", *extra)
        assert proc.returncode == 0, proc.stderr
        status = _chromium(out.as_uri() + "#t=0.12", tmp_path / f"{name}.png", tmp_path / "profile")
        pages[name] = (out, status, _scene_pixels(tmp_path / f"{name}.png", status))
    worn_cells = sum(1 for r in pq.read_table(worn_run / "wear_map.parquet").to_pylist() if r["surface"] == "tube")
    (_, s_plain, p_plain), (worn, s_worn, p_worn) = pages["plain"], pages["worn"]

    assert s_worn["data-scale"] == s_plain["data-scale"] == "20"
    assert "DISPLACEMENT SCALE" in worn.read_text(encoding="utf-8") and "20 times true size" in worn.read_text(encoding="utf-8")
    assert s_worn["data-drawn-wear"] == "true" and int(s_worn["data-wear-faces"]) == 2 * worn_cells > 0
    assert s_plain["data-wear-faces"] == "0" and s_plain["data-drawn-wear"] == "false"
    _assert_drawn(p_plain)
    _assert_drawn(p_worn)
    # the wear colour bar sits on the scene's left: compare the rest of the scene
    left = 220
    assert int(_worn_coloured(p_plain[:, left:]).sum()) < 5
    assert int(_worn_coloured(p_worn[:, left:]).sum()) >= 30
