"""The page at ``GET /`` in a real headless Chromium: its numbers are the API's, it draws the body,
animates the motion, shows errors beside their inputs, and the API docs render offline.

The numbers the page shows carry the API's value in ``data-value`` (the shortest round-trip decimal of
the double, which JavaScript and Python write alike); each is compared with the JSON the API answers
for the same file, fetched here with httpx, and the displayed text with it to its printed digits.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any, cast

import httpx
import pytest

from .conftest import Console, Server

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_meshes"
DISPLAY_REL = 1e-9  # the table prints 10 significant digits
PHONE = {"width": 390, "height": 844}

# reads the 3-D canvas back (it keeps its drawing buffer) over a region given as fractions of its size:
# the fraction of pixels unlike the background, and a hash of the region
PIXELS = """([x0, y0, x1, y1]) => {
  const c = document.querySelector('#viewer canvas');
  const off = document.createElement('canvas'); off.width = c.width; off.height = c.height;
  const ctx = off.getContext('2d'); ctx.drawImage(c, 0, 0);
  const [a, b, w, h] = [x0 * c.width, y0 * c.height, (x1 - x0) * c.width, (y1 - y0) * c.height].map(Math.round);
  const d = ctx.getImageData(a, b, w, h).data;
  let differ = 0, hash = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (Math.abs(d[i] - 0xee) + Math.abs(d[i + 1] - 0xf2) + Math.abs(d[i + 2] - 0xf7) > 30) differ += 1;
    hash = (hash * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) | 0;
  }
  return {fraction: differ / (d.length / 4), hash};
}"""
CANVAS_HASH = """(id) => {
  const c = document.getElementById(id);
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let h = 0;
  for (let i = 0; i < d.length; i += 16) h = (h * 31 + d[i] + 3 * d[i + 1] + 5 * d[i + 2] + 7 * d[i + 3]) | 0;
  return h;
}"""
CENTRE = [0.35, 0.35, 0.65, 0.65]


def open_page(page: Any, server: Server) -> None:
    page.goto(f"{server.url}/")
    page.wait_for_selector("body[data-state=idle]")


def analyze(page: Any, path: Path | None = None, **fields: str) -> str:
    if path is not None:
        page.set_input_files("#file", str(path))
    for name, value in fields.items():
        if page.locator(f"select#{name}").count():
            page.select_option(f"#{name}", value)
        else:
            page.fill(f"#{name}", value)
    page.click("#analyze")
    page.wait_for_selector("body[data-state=ready], body[data-state=error]")
    return str(page.evaluate("document.body.dataset.state"))


def api_mesh(server: Server, path: Path, **params: str) -> dict[str, Any]:
    with path.open("rb") as f:
        r = httpx.post(f"{server.url}/v1/analyze/mesh", params=params, files={"file": (path.name, f)}, timeout=120)
    assert r.status_code == 200, r.text
    return cast("dict[str, Any]", r.json())


def shown_numbers(page: Any) -> dict[str, tuple[str, str]]:
    """data-key -> (data-value, displayed text) of every number in the results table."""
    items = page.eval_on_selector_all("#results-table .num", "els => els.map(e => [e.dataset.key, e.dataset.value, e.textContent])")
    return {key: (value, text) for key, value, text in items}


def at(result: Any, key: str) -> Any:
    for part in key.split("."):
        result = result[int(part)] if isinstance(result, list) else result[part]
    return result


def assert_numbers_match(page: Any, result: dict[str, Any]) -> dict[str, tuple[str, str]]:
    shown = shown_numbers(page)
    required = [
        "mass",
        "center_of_mass.0",
        "center_of_mass.2",
        "inertia_tensor.0.1",
        "inertia_tensor.2.2",
        "principal.moments.0",
        "principal.moments.2",
        "principal.axes.1.1",
        "diagnostics.relative_error_estimate",
        "diagnostics.elapsed_s",
    ]
    if "volume" in result:
        required.append("volume")
    assert set(required) <= set(shown), sorted(set(required) - set(shown))
    for key, (value, text) in shown.items():
        if key == "diagnostics.elapsed_s":
            continue  # the page's own request took its own time
        expected = at(result, key)
        assert float(value) == expected, key
        assert float(text) == pytest.approx(expected, rel=DISPLAY_REL, abs=1e-300), key
    return shown


@pytest.mark.parametrize("name", ["box.stl", "l_bracket.stl", "tetrahedron.stl", "needle.obj", "plate.obj", "two_density.vtu"])
def test_page_numbers_are_the_apis_for_sample_meshes(console_page: tuple[Any, Console], server: Server, name: str) -> None:
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, SAMPLES / name) == "ready"
    result = api_mesh(server, SAMPLES / name)
    assert_numbers_match(page, result)
    kind = result["classification"]["kind"].replace("_", " ")
    assert kind in page.inner_text("[data-row=class]")
    assert page.inner_text("[data-row=warnings]").strip() != ""


def test_units_and_mass_options_reach_the_api(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, SAMPLES / "box.stl", units="mm", mass="2.5", tolerance="1e-4") == "ready"
    result = api_mesh(server, SAMPLES / "box.stl", units="mm", mass="2.5", tolerance="1e-4")
    shown = assert_numbers_match(page, result)
    assert float(shown["mass"][0]) == 2.5


def test_pasted_point_masses_match_the_points_endpoint(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    page.click("#paste-box summary")
    text = (SAMPLES / "triatomic.json").read_text()
    page.fill("#paste", text)
    assert analyze(page) == "ready"
    result = httpx.post(f"{server.url}/v1/analyze/points", json=json.loads(text), timeout=60).json()
    assert_numbers_match(page, result)
    assert "planar" in page.inner_text("[data-row=class]")
    page.fill("#paste", "mass,x,y,z\n1,-1,0,0\n1,1,0,0\n16,0,1,0\n")
    assert analyze(page) == "ready"
    assert_numbers_match(page, result)  # the same body written as CSV


def test_view_draws_the_body_axes_and_ellipsoid(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, SAMPLES / "l_bracket.stl") == "ready"
    everything = page.evaluate(PIXELS, CENTRE)
    for layer in ("axes", "ellipsoid"):
        page.uncheck(f"#show-{layer}")
    body_only = page.evaluate(PIXELS, CENTRE)
    page.uncheck("#show-body")
    nothing = page.evaluate(PIXELS, CENTRE)
    page.check("#show-ellipsoid")
    ellipsoid_only = page.evaluate(PIXELS, CENTRE)
    # the body covers the middle of the view; without it only the centre-of-mass dot is left there
    assert body_only["fraction"] > 0.3
    assert nothing["fraction"] < 0.05
    assert ellipsoid_only["fraction"] > 0.3
    assert everything["hash"] != body_only["hash"]
    assert page.evaluate("window.inertiaPage.viewer.layers.axes.children.length") >= 7  # 3 arrows, 3 back lines, labels


def test_assembly_parts_get_distinct_colours(console_page: tuple[Any, Console], server: Server, tmp_path: Path) -> None:
    trimesh = pytest.importorskip("trimesh")
    scene = trimesh.Scene()
    scene.add_geometry(
        trimesh.creation.box((1, 1, 1)),
        node_name="left",
        geom_name="left",
        transform=trimesh.transformations.translation_matrix((-1, 0, 0)),
    )
    scene.add_geometry(
        trimesh.creation.box((1, 2, 1)),
        node_name="right",
        geom_name="right",
        transform=trimesh.transformations.translation_matrix((1.5, 0, 0)),
    )
    path = tmp_path / "pair.glb"
    path.write_bytes(scene.export(file_type="glb"))
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, path) == "ready"
    assert_numbers_match(page, api_mesh(server, path))
    colours = page.evaluate(
        "window.inertiaPage.viewer.layers.body.children"
        ".filter(o => o.isMesh && o.geometry.type !== 'SphereGeometry')"
        ".map(o => o.material.color.getHexString())"
    )
    assert len(colours) == 2 and len(set(colours)) == 2
    assert page.locator("[data-row=parts] li").count() == 2


def test_formats_the_browser_cannot_parse_show_the_ellipsoid_and_say_so(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, SAMPLES / "two_density.vtu") == "ready"
    assert "does not draw VTU" in page.inner_text("#view-note")
    assert page.evaluate(PIXELS, CENTRE)["fraction"] > 0.3  # the ellipsoid


def test_large_meshes_are_drawn_decimated_with_a_note(console_page: tuple[Any, Console], server: Server, tmp_path: Path) -> None:
    trimesh = pytest.importorskip("trimesh")
    sphere = trimesh.creation.icosphere(subdivisions=7)  # 327,680 triangles
    path = tmp_path / "sphere.stl"
    path.write_bytes(sphere.export(file_type="stl"))
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, path) == "ready"
    note = page.inner_text("#view-note")
    assert "decimated" in note and "327,680" in note
    shown = page.evaluate("window.inertiaPage.viewer.layers.body.children[0].geometry.attributes.position.count / 3")
    assert 1000 < shown <= 200_000
    assert page.evaluate(PIXELS, CENTRE)["fraction"] > 0.5


def test_motion_animates_and_shows_the_tennis_racket_flips(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    # box 1 x 2 x 3: y is the intermediate axis (I = 5000 of 2500, 5000, 6500); spun nearly about it
    assert analyze(page, SAMPLES / "box.stl", omega="0.01,1,0.01", duration="100", samples="800") == "ready"
    assert page.is_visible("#motion")
    assert "no" in page.inner_text("[data-row=stable]")
    trajectory = page.evaluate("window.inertiaPage.trajectory")
    direct = api_mesh(server, SAMPLES / "box.stl", omega="0.01,1,0.01", duration="100", samples="800")
    assert trajectory == direct["precession"]["trajectory"]
    omega2 = [w[1] for w in trajectory["omega_body"]]
    assert min(omega2) < -0.9 and max(omega2) > 0.9  # Ω2 reverses: the flips are in what is drawn
    before = (page.evaluate(PIXELS, [0, 0, 1, 1])["hash"], page.evaluate(CANVAS_HASH, "plot-polhode"))
    page.click("#play")
    page.wait_for_function("window.inertiaPage.time > 2")
    after = (page.evaluate(PIXELS, [0, 0, 1, 1])["hash"], page.evaluate(CANVAS_HASH, "plot-polhode"))
    assert before[0] != after[0] and before[1] != after[1]
    page.click("#play")  # pause
    paused_at = page.evaluate("window.inertiaPage.time")
    page.wait_for_timeout(300)
    assert page.evaluate("window.inertiaPage.time") == paused_at
    page.fill("#time", "500")  # the slider seeks: half-way
    assert page.evaluate("window.inertiaPage.time") == pytest.approx(50, abs=0.2)
    assert re.search(r"t = 50\.\d\d s", page.inner_text("#time-out"))


def test_motion_without_duration_asks_for_a_few_periods(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, SAMPLES / "tetrahedron.stl", omega="0.2,0.1,1") == "ready"
    result = page.evaluate("window.inertiaPage.result")
    trajectory = page.evaluate("window.inertiaPage.trajectory")
    assert result["precession"]["regime"] == "regular_precession"
    rate = result["precession"]["space_precession_rate"]
    assert trajectory["t"][-1] == pytest.approx(3 * 2 * 3.141592653589793 / rate)
    assert len(page.evaluate("window.inertiaPage.viewer.spaceCone.children")) > 0  # the cones are drawn


@pytest.mark.parametrize(
    ("name", "fields", "where", "words"),
    [
        ("open_box.stl", {}, "#file-error", "watertight"),
        ("box.stl", {"density": "-1"}, "#density-error", "density"),
        ("box.stl", {"model": "shell"}, "#thickness-error", "thickness"),
        ("box.stl", {"units": "furlong"}, "#units-error", "unit"),
        ("box.stl", {"omega": "1,2"}, "#omega-error", "three numbers"),
        ("box.stl", {"omega": "0,1,0", "samples": "0", "duration": "1"}, "#samples-error", "samples"),
    ],
)
def test_errors_appear_next_to_the_input_that_caused_them(
    console_page: tuple[Any, Console], server: Server, name: str, fields: dict[str, str], where: str, words: str
) -> None:
    page, console = console_page
    console.expect_http_errors = True
    open_page(page, server)
    if fields.get("units") == "furlong":  # not in the list: add it, as a hand-edited request would
        page.evaluate("document.getElementById('units').append(new Option('furlong'))")
    assert analyze(page, SAMPLES / name, **fields) == "error"
    assert page.is_visible(where)
    assert words in page.inner_text(where).lower()
    field = where.removeprefix("#").removesuffix("-error")
    assert page.get_attribute(f"#{field}", "aria-invalid") == "true"
    assert page.is_hidden("#results")


def test_an_unreadable_file_and_bad_pasted_text_get_readable_messages(
    console_page: tuple[Any, Console], server: Server, tmp_path: Path
) -> None:
    page, console = console_page
    console.expect_http_errors = True
    open_page(page, server)
    bad = tmp_path / "garbage.stl"
    bad.write_bytes(b"solid nothing\nthis is not an stl\n")
    assert analyze(page, bad) == "error"
    assert "(" in page.inner_text("#file-error")  # message then (code)
    other = tmp_path / "notes.txt"
    other.write_text("hello")
    assert analyze(page, other) == "error"
    assert "unsupported_format" in page.inner_text("#file-error")
    page.set_input_files("#file", [])
    page.evaluate("window.inertiaPage.file = null")
    page.click("#paste-box summary")
    page.fill("#paste", '[{"mass": -1, "position": [0, 0, 0]}]')
    assert analyze(page) == "error"
    assert page.is_visible("#paste-error") and "mass" in page.inner_text("#paste-error")
    page.fill("#paste", '[{"mass": 1, "position": [0, 0, 0]}, {"mass": 1, "position": [1, 0, 0]}]')
    assert analyze(page, density="7850") == "error"
    assert "leave density empty" in page.inner_text("#density-error")


def test_download_buttons_give_the_json_and_the_offered_snippets(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, SAMPLES / "box.stl") == "ready"
    with page.expect_download() as info:
        page.click("#dl-json")
    saved = json.loads(Path(info.value.path()).read_text())
    assert saved == page.evaluate("window.inertiaPage.result")
    schema = httpx.get(f"{server.url}/openapi.json").json()
    offered = any(p["name"] == "export" for p in schema["paths"]["/v1/analyze/mesh"]["post"]["parameters"])
    buttons = page.locator("button.export")
    if not offered:  # the service has no snippets: the buttons are hidden
        assert all(not buttons.nth(i).is_visible() for i in range(buttons.count()))
        return
    for fmt in ("urdf", "sdf", "mjcf"):
        with page.expect_download() as info:
            page.click(f"button[data-export={fmt}]")
        expected = api_mesh(server, SAMPLES / "box.stl", export=fmt)["export"]["text"]
        assert Path(info.value.path()).read_text() == expected


@pytest.mark.parametrize("console_page", [PHONE], indirect=True)
def test_phone_layout_fits_the_screen(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    assert analyze(page, SAMPLES / "box.stl", omega="0.01,1,0.01", duration="60", samples="300") == "ready"
    assert page.evaluate("document.scrollingElement.scrollWidth") <= PHONE["width"]
    box = page.locator("#viewer").bounding_box()
    assert box["width"] > 300 and box["height"] > 200
    assert page.evaluate(PIXELS, CENTRE)["fraction"] > 0.2
    for control in ("#analyze", "#play", "#time", "#dl-json"):
        b = page.locator(control).bounding_box()
        assert b["x"] >= 0 and b["x"] + b["width"] <= PHONE["width"]


def test_controls_have_labels_and_are_keyboard_reachable(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    unlabelled = page.evaluate("""() => [...document.querySelectorAll('input, select, textarea, button')]
      .filter(e => !(e.labels && e.labels.length) && !e.getAttribute('aria-label') && !e.textContent.trim())
      .map(e => e.id || e.outerHTML)""")
    assert unlabelled == []
    seen = []
    for _ in range(40):
        page.keyboard.press("Tab")
        seen.append(page.evaluate("document.activeElement.id"))
        if seen[-1] == "analyze":
            break
    assert {"file", "units", "density", "omega", "method", "analyze"} <= set(seen)
    page.set_input_files("#file", str(SAMPLES / "tetrahedron.stl"))
    page.focus("#analyze")
    page.keyboard.press("Enter")
    page.wait_for_selector("body[data-state=ready]")
    page.focus("#viewer")  # the view turns and zooms from the keyboard too
    before = page.evaluate(PIXELS, [0, 0, 1, 1])["hash"]
    page.keyboard.press("Shift+ArrowLeft")
    turned = page.evaluate(PIXELS, [0, 0, 1, 1])["hash"]
    page.keyboard.press("+")
    zoomed = page.evaluate(PIXELS, [0, 0, 1, 1])["hash"]
    assert len({before, turned, zoomed}) == 3


@pytest.mark.parametrize(("path", "text"), [("/docs", "/v1/analyze/mesh"), ("/redoc", "/v1/analyze/mesh")])
def test_api_docs_render_offline(console_page: tuple[Any, Console], server: Server, path: str, text: str) -> None:
    page, console = console_page
    page.goto(f"{server.url}{path}")
    page.wait_for_function(f"document.body.innerText.includes({json.dumps(text)})")
    for endpoint in ("/v1/analyze/points", "/v1/precession", "/v1/batch", "/v1/formats"):
        assert endpoint in page.inner_text("body")
    assert console.external == []


WATER_XYZ = """3
water, experimental equilibrium geometry (angstrom)
O  0.000000  0.000000  0.117300
H  0.000000  0.757200 -0.469200
H  0.000000 -0.757200 -0.469200
"""


def test_a_pasted_xyz_molecule_is_the_apis_xyz_file(console_page: tuple[Any, Console], server: Server, tmp_path: Path) -> None:
    page, _ = console_page
    open_page(page, server)
    page.click("#paste-box summary")
    page.fill("#paste", WATER_XYZ)
    assert analyze(page) == "ready"
    path = tmp_path / "water.xyz"
    path.write_text(WATER_XYZ)
    result = api_mesh(server, path)
    assert_numbers_match(page, {**result, "source": {**result["source"], "filename": "pasted.xyz"}})
    if "rotational_constants" in result:
        assert "MHz" in page.inner_text("[data-row=rotational_constants]")
    assert page.evaluate("window.inertiaPage.viewer.layers.body.children.length") == 3  # one sphere per atom


def test_a_dropped_file_is_analysed(console_page: tuple[Any, Console], server: Server) -> None:
    page, _ = console_page
    open_page(page, server)
    data = list((SAMPLES / "tetrahedron.stl").read_bytes())
    transfer = page.evaluate_handle(
        """(bytes) => {
      const dt = new DataTransfer();
      dt.items.add(new File([new Uint8Array(bytes)], 'tetrahedron.stl'));
      return dt;
    }""",
        data,
    )
    page.dispatch_event("#drop", "dragover", {"dataTransfer": transfer})
    page.dispatch_event("#drop", "drop", {"dataTransfer": transfer})
    page.wait_for_selector("body[data-state=ready]")
    assert_numbers_match(page, api_mesh(server, SAMPLES / "tetrahedron.stl"))
    assert "tetrahedron.stl" in page.inner_text("#file-formats")


def test_a_server_with_an_api_key_is_used_with_the_key(browser: Any, tmp_path: Path) -> None:
    server = Server(INERTIA_API_KEY="sesame")
    try:
        context = browser.new_context()
        page = context.new_page()
        console = Console(page, server)
        open_page(page, server)
        assert "API key" in page.inner_text("#file-formats")
        page.fill("#apikey", "sesame")
        page.dispatch_event("#apikey", "change")
        page.wait_for_function("window.inertiaPage.formats.length > 0")
        assert analyze(page, SAMPLES / "box.stl", omega="0.01,1,0.01") == "ready"
        assert page.evaluate("window.inertiaPage.trajectory.t.length") == 600
        context.close()
        assert console.errors == []
        assert all("401" in e for e in console.http_errors)  # the first look, before the key was given
    finally:
        server.stop()


def test_an_export_the_api_refuses_disables_its_button_with_the_reason(console_page: tuple[Any, Console], server: Server) -> None:
    page, console = console_page
    console.expect_http_errors = True
    open_page(page, server)
    page.click("#paste-box summary")
    page.fill("#paste", "1,0,0,0\n1,1,0,0\n")  # two points: a linear rotator, which simulators reject
    assert analyze(page) == "ready"
    if not page.locator("button[data-export=urdf]").is_visible():
        pytest.skip("this service offers no export")
    page.click("button[data-export=urdf]")
    page.wait_for_selector("#export-error:not([hidden])")
    assert "invalid_inertia" in page.inner_text("#export-error")
    assert page.is_disabled("button[data-export=urdf]")
    assert page.is_enabled("#dl-json")
