"""Without a browser: the page and the docs reference only files the app serves itself (no CDN),
and the vendored libraries ship with their licences and pinned versions."""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator

import pytest

with warnings.catch_warnings():  # starlette deprecates httpx for TestClient in favour of httpx2
    warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
    from fastapi.testclient import TestClient

from inertia.api import Settings, create_app
from inertia.web import STATIC_DIR

ASSET = re.compile(r"""(?:src|href)=["']([^"'#]+)["']""")


@pytest.fixture(scope="module")
def client() -> Iterator[TestClient]:
    with TestClient(create_app(Settings(compute_processes=1))) as c:
        yield c


@pytest.mark.parametrize("path", ["/", "/docs", "/redoc"])
def test_pages_load_only_local_assets(client: TestClient, path: str) -> None:
    r = client.get(path)
    assert r.status_code == 200 and r.headers["content-type"].startswith("text/html")
    assets = [a for a in ASSET.findall(r.text) if not a.startswith(("http://", "https://")) or "127.0.0.1" in a]
    external = [a for a in ASSET.findall(r.text) if a.startswith(("http://", "https://", "//"))]
    assert external == []
    for asset in assets:
        if asset.startswith("data:") or asset in ("docs", "redoc"):
            continue
        url = asset if asset.startswith("/") else f"/{asset}"
        assert client.get(url).status_code == 200, url


def test_page_modules_and_import_map_resolve(client: TestClient) -> None:
    html = client.get("/").text
    for target in re.findall(r'"\./(static/[^"]+)"', html):
        if target.endswith("/"):
            continue
        assert client.get(f"/{target}").status_code == 200, target
    for module in ("app.js", "view3d.js", "plots.js", "meshes.js"):
        source = client.get(f"/static/{module}").text
        for relative in re.findall(r"from '\./([^']+)'", source):
            assert client.get(f"/static/{relative}").status_code == 200, relative
        for addon in re.findall(r"from 'three/addons/([^']+)'", source):
            assert client.get(f"/static/vendor/three/addons/{addon}").status_code == 200, addon


def test_vendored_libraries_carry_licences_and_versions() -> None:
    vendor = STATIC_DIR / "vendor"
    readme = (vendor / "README.md").read_text()
    for folder, version in (("three", "0.181.0"), ("swagger-ui", "5.30.2"), ("redoc", "2.5.1")):
        assert (vendor / folder / "LICENSE").stat().st_size > 500
        assert version in readme
    assert '"181"' in (vendor / "three" / "three.core.min.js").read_text()  # three.REVISION
    for path in vendor.rglob("*.js"):
        assert "cdn." not in path.read_text(errors="replace"), path


def test_a_missing_static_file_is_a_404_envelope(client: TestClient) -> None:
    r = client.get("/static/no-such-file.js")
    assert r.status_code == 404
    assert r.json()["error"]["code"] == "not_found"
