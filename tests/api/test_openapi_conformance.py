"""The OpenAPI schema is what the service sends: real responses of every endpoint, and of every
error status, validated against the schema the service publishes at /openapi.json.

Each case is a real request to the application; its response's status must be documented for
that operation, with the response's content type, and the body must validate (JSON Schema 2020-12,
``$ref`` resolved in the document) against the documented schema. Response models forbid keys
they do not name, so a section the result model writes and the schema does not describe fails here.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
    from fastapi.testclient import TestClient

from inertia.api import Settings, create_app
from tests.support.meshes import box_stl, stl_bytes, torus_stl

jsonschema_rs = pytest.importorskip("jsonschema_rs")

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_meshes"
BOX = box_stl(1, 2, 3)
OPEN = stl_bytes(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]), np.array([[0, 2, 1], [0, 1, 3]]))
ERROR_STATUSES = (401, 413, 415, 422, 500, 503)

Call = Callable[[Any], Any]


def _client(settings: Settings) -> Iterator[Any]:
    with TestClient(create_app(settings), raise_server_exceptions=False) as c:
        yield c


@pytest.fixture(scope="module")
def client() -> Iterator[Any]:
    yield from _client(Settings(compute_processes=1))


@pytest.fixture(scope="module")
def spec(client: Any) -> dict[str, Any]:
    doc: dict[str, Any] = client.get("/openapi.json").json()
    return doc


def _validator(spec: dict[str, Any], schema: dict[str, Any]) -> Any:
    # the whole document as the root, so "#/components/schemas/..." resolves; its other keys are not keywords
    root = {key: value for key, value in spec.items() if key != "paths"}
    return jsonschema_rs.Draft202012Validator({**root, **schema})


def _schema_ref(spec: dict[str, Any], name: str) -> Any:
    return _validator(spec, {"$ref": f"#/components/schemas/{name}"})


def check(spec: dict[str, Any], method: str, path: str, response: Any) -> Any:
    """Assert that ``response`` is one the schema documents for this operation; return its JSON."""
    operation = spec["paths"][path][method]
    status = str(response.status_code)
    assert status in operation["responses"], f"{method.upper()} {path} answered {status}, which is undocumented"
    documented = operation["responses"][status]
    media = response.headers["content-type"].split(";")[0]
    assert media in documented.get("content", {}), f"{status} {media} is not documented for {path}"
    schema = documented["content"][media]["schema"]
    if response.status_code >= 400:  # the envelope, not FastAPI's {"detail": ...}, which it would also pass
        assert schema == {"$ref": "#/components/schemas/ErrorOut"}, (path, status, schema)
    if media == "application/json":
        body = response.json()
        errors = [str(e) for e in _validator(spec, schema).iter_errors(body)]
        assert not errors, (method, path, status, errors[:5], body)
        return body
    return response.text


def mesh(data: bytes, name: str = "part.stl", **params: Any) -> Call:
    return lambda c: c.post("/v1/analyze/mesh", params=params, files={"file": (name, data)})


def points(body: Any) -> Call:
    return lambda c: c.post("/v1/analyze/points", json=body)


def prec(body: Any) -> Call:
    return lambda c: c.post("/v1/precession", json=body)


def _scene_glb() -> bytes:
    trimesh = pytest.importorskip("trimesh")
    a = trimesh.creation.box((1, 1, 1))
    b = trimesh.creation.box((1, 2, 1))
    b.apply_translation((3, 0, 0))
    scene = trimesh.Scene()
    scene.add_geometry(a, node_name="a", geom_name="a")
    scene.add_geometry(b, node_name="b", geom_name="b")
    data: bytes = scene.export(file_type="glb")
    return data


def _step_box() -> bytes:
    pytest.importorskip("OCP")
    import tempfile

    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    writer = STEPControl_Writer()
    writer.Transfer(BRepPrimAPI_MakeBox(10.0, 20.0, 30.0).Shape(), STEPControl_AsIs)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "box.step")
        writer.Write(path)
        return Path(path).read_bytes()


TRIATOMIC = json.loads((SAMPLES / "triatomic.json").read_text())["points"]
WATER = [
    {"element": "O", "position": [0, 0, 0.1173]},
    {"element": "H", "position": [0, 0.7572, -0.4692]},
    {"element": "H", "position": [0, -0.7572, -0.4692]},
]

# (name, path, request): every section of the result model appears in at least one of these
OK_CASES: list[tuple[str, str, Callable[[], Call]]] = [
    ("box", "/v1/analyze/mesh", lambda: mesh(BOX)),
    (
        "box every option",
        "/v1/analyze/mesh",
        lambda: mesh(
            BOX,
            units="mm",
            density=7850,
            reference="1,-2,3",
            omega="0.1,0.2,1",
            duration=5,
            samples=7,
            export="urdf",
            frame="0.5,0.5,0.5,0.5",
        ),
    ),
    (
        "asymmetric top, unstable",
        "/v1/analyze/mesh",
        lambda: mesh(BOX, omega="0.01,1,0.01", duration=2, samples=3, method="dop853"),
    ),
    ("symmetric top", "/v1/analyze/mesh", lambda: mesh(box_stl(1, 1, 3), omega="0.1,0,1", export="mjcf")),
    (
        "shell",
        "/v1/analyze/mesh",
        lambda: mesh((SAMPLES / "open_box.stl").read_bytes(), "open_box.stl", model="shell", thickness=0.001, export="sdf"),
    ),
    (
        "volume mesh",
        "/v1/analyze/mesh",
        lambda: mesh((SAMPLES / "two_density.vtu").read_bytes(), "two.vtu", mass=3.0, frame="1,0,0,0", reference="0,0,0"),
    ),
    (
        "scene",
        "/v1/analyze/mesh",
        lambda: mesh(_scene_glb(), "scene.glb", densities='{"a": 1000, "b": 2000}', export="urdf", omega="0,0,1"),
    ),
    ("cad tessellated", "/v1/analyze/mesh", lambda: mesh(_step_box(), "box.step", geometry="mesh", deflection=0.01)),
    ("cad brep", "/v1/analyze/mesh", lambda: mesh(_step_box(), "box.step")),
    (
        "points with trajectory",
        "/v1/analyze/points",
        lambda: points(
            {"points": TRIATOMIC, "omega": [1, 2, 3], "duration": 1.0, "samples": 3, "method": "rk45", "reference": [0, 0, 0]}
        ),
    ),
    ("molecule", "/v1/analyze/points", lambda: points({"points": WATER, "units": "angstrom"})),
    (
        "linear molecule",
        "/v1/analyze/points",
        lambda: points(
            {
                "points": [
                    {"element": "O", "position": [0, 0, -1.16]},
                    {"element": "C", "position": [0, 0, 0]},
                    {"element": "O", "position": [0, 0, 1.16]},
                ],
                "units": "angstrom",
                "omega": [1, 0, 0],
            }
        ),
    ),
    (
        "precession from a tensor",
        "/v1/precession",
        lambda: prec(
            {"inertia_tensor": [[2, 0.1, 0], [0.1, 3, 0], [0, 0, 4]], "omega": [0.1, 0, 1], "duration": 3.0, "samples": 4}
        ),
    ),
    (
        "precession from moments",
        "/v1/precession",
        lambda: prec(
            {"principal_moments": [1, 2, 3], "omega": [0.01, 1, 0.01], "method": "splitting", "duration": 2.0, "samples": 3}
        ),
    ),
    ("precession at rest", "/v1/precession", lambda: prec({"principal_moments": [1, 1, 1], "omega": [0, 0, 0]})),
]


@pytest.mark.parametrize(("name", "path", "request_"), OK_CASES, ids=[c[0] for c in OK_CASES])
def test_every_result_validates_against_the_schema(
    client: Any, spec: dict[str, Any], name: str, path: str, request_: Callable[[], Call]
) -> None:
    response = request_()(client)
    assert response.status_code == 200, response.text
    check(spec, "post", path, response)


def _reachable(spec: dict[str, Any], name: str, seen: set[str]) -> set[str]:
    if name not in seen:
        seen.add(name)
        for ref in _refs(spec["components"]["schemas"][name]):
            _reachable(spec, ref, seen)
    return seen


def _refs(node: Any) -> Iterator[str]:
    if isinstance(node, dict):
        for key, value in node.items():
            if key == "$ref":
                yield value.rsplit("/", 1)[-1]
            else:
                yield from _refs(value)
    elif isinstance(node, list):
        for value in node:
            yield from _refs(value)


def test_result_schemas_forbid_keys_they_do_not_name(spec: dict[str, Any]) -> None:
    # so a response with a section the schema does not describe fails validation instead of passing through
    names = set().union(*(_reachable(spec, n, set()) for n in ("AnalysisOut", "PrecessionResponse", "ErrorOut")))
    assert {"SourceOut", "DiagnosticsOut", "PartOut", "PrecessionOut", "FrameOut", "ExportOut"} <= names
    for name in names:
        schema = spec["components"]["schemas"][name]
        if schema.get("type") == "object":
            assert schema.get("additionalProperties") is False, name


def test_service_endpoints_validate_against_the_schema(client: Any, spec: dict[str, Any]) -> None:
    assert check(spec, "get", "/healthz", client.get("/healthz")) == {"status": "ok"}
    assert "stl" in check(spec, "get", "/v1/formats", client.get("/v1/formats"))["surface"]


def test_batch_lines_validate_as_results_or_envelopes(client: Any, spec: dict[str, Any]) -> None:
    files = [("files", ("a.stl", BOX)), ("files", ("open.stl", OPEN)), ("files", ("c.dwg", BOX))]
    response = client.post("/v1/batch", params={"omega": "0,0,1"}, files=files)
    assert response.status_code == 200
    text = check(spec, "post", "/v1/batch", response)
    lines = [json.loads(line) for line in text.splitlines() if line]
    assert len(lines) == 3
    result, error = _schema_ref(spec, "AnalysisOut"), _schema_ref(spec, "ErrorOut")
    for line in lines:
        if "error" in line:
            errors = [str(e) for e in error.iter_errors({"error": line["error"]})]
            assert set(line) == {"source", "error"} and not errors, (line, errors)
        else:
            assert not [str(e) for e in result.iter_errors(line)]
    assert [("error" in line) for line in lines] == [False, True, True]


# (expected status, code, settings, path, request)
ERROR_CASES: list[tuple[int, str, dict[str, Any], str, Call]] = [
    (401, "unauthorized", {"api_key": "s3cret"}, "/v1/analyze/mesh", mesh(BOX)),
    (401, "unauthorized", {"api_key": "s3cret"}, "/v1/precession", prec({"principal_moments": [1, 2, 3], "omega": [0, 0, 1]})),
    (413, "payload_too_large", {"max_upload_bytes": 1000}, "/v1/analyze/mesh", mesh(box_stl(1, 2, 3) * 3)),
    (
        413,
        "payload_too_large",
        {"max_upload_bytes": 1000},
        "/v1/analyze/points",
        points({"points": [{"mass": 1.0, "position": [i, 0, 0]} for i in range(100)]}),
    ),
    (415, "unsupported_format", {}, "/v1/analyze/mesh", mesh(BOX, "part.dwg")),
    (422, "invalid_parameter", {}, "/v1/analyze/mesh", mesh(BOX, density=-1)),
    (422, "invalid_parameter", {}, "/v1/analyze/mesh", mesh(BOX, density=1, mass=2)),
    (422, "invalid_parameter", {}, "/v1/analyze/mesh", mesh(BOX, omega="0,0,1", duration=1, samples=10**9)),
    (422, "not_watertight", {}, "/v1/analyze/mesh", mesh(OPEN)),
    (422, "invalid_parameter", {}, "/v1/analyze/points", points({"points": []})),
    (
        422,
        "invalid_inertia",
        {},
        "/v1/analyze/points",
        points({"points": [{"mass": 1.0, "position": [0, 0, 0]}], "export": "urdf"}),
    ),
    (422, "invalid_parameter", {}, "/v1/precession", prec({"principal_moments": [1, 2, 3]})),
    (
        422,
        "invalid_parameter",
        {},
        "/v1/batch",
        lambda c: c.post("/v1/batch", params={"units": "parsec"}, files=[("files", ("a.stl", BOX))]),
    ),
    (503, "timeout", {"timeout_s": 0.05}, "/v1/analyze/mesh", mesh(torus_stl(500, 500))),
]


@pytest.mark.parametrize(
    ("status", "code", "settings", "path", "request_"), ERROR_CASES, ids=[f"{c[0]}-{c[1]}-{c[3]}" for c in ERROR_CASES]
)
def test_every_error_status_validates_against_the_schema(
    status: int, code: str, settings: dict[str, Any], path: str, request_: Call
) -> None:
    for c in _client(Settings(compute_processes=1, **settings)):
        app_spec = c.get("/openapi.json").json()
        response = request_(c)
        assert response.status_code == status, response.text
        body = check(app_spec, "post", path, response)
        assert body["error"]["code"] == code


def test_an_internal_error_validates_against_the_schema(monkeypatch: pytest.MonkeyPatch) -> None:
    from inertia.api import routes

    async def broken(*args: Any) -> dict[str, Any]:
        raise RuntimeError("a bug")

    monkeypatch.setattr(routes, "_small_or_pooled", broken)
    for c in _client(Settings(compute_processes=1)):
        response = prec({"principal_moments": [1, 2, 3], "omega": [0, 0, 1]})(c)
        assert response.status_code == 500
        assert check(c.get("/openapi.json").json(), "post", "/v1/precession", response)["error"]["code"] == "internal_error"


def test_every_error_status_is_documented_with_the_envelope_and_valid_examples(spec: dict[str, Any]) -> None:
    envelope = _schema_ref(spec, "ErrorOut")
    expected = {
        "/v1/analyze/mesh": {413, 415, 422, 500, 503},
        "/v1/analyze/points": {413, 422, 500, 503},
        "/v1/precession": {413, 422, 500, 503},
        "/v1/batch": {413, 422, 500, 503},
    }
    for path, statuses in expected.items():
        responses = spec["paths"][path]["post"]["responses"]
        assert statuses <= {int(s) for s in responses}, path
        for status in statuses:
            content = responses[str(status)]["content"]["application/json"]
            assert content["schema"] == {"$ref": "#/components/schemas/ErrorOut"}
            examples = content["examples"]
            assert examples, (path, status)
            for name, example in examples.items():
                value = example["value"]
                assert not list(envelope.iter_errors(value)), (path, status, name)
                assert value["error"]["code"] == name
    # FastAPI's own {"detail": ...} shape is documented nowhere: the service never sends it
    assert "HTTPValidationError" not in spec["components"]["schemas"]
    assert '"detail"' not in json.dumps(spec["paths"])
    codes415 = spec["paths"]["/v1/analyze/mesh"]["post"]["responses"]["415"]["content"]["application/json"]
    assert set(codes415["examples"]) == {"unsupported_format"}


def test_the_api_key_scheme_is_documented_where_a_key_is_required() -> None:
    for c in _client(Settings(compute_processes=1, api_key="s3cret")):
        spec = c.get("/openapi.json").json()
    schemes = spec["components"]["securitySchemes"]
    described = [{k: s[k] for k in ("type", "in", "name")} for s in schemes.values()]
    assert described == [{"type": "apiKey", "in": "header", "name": "X-API-Key"}]
    (name,) = schemes
    for path, item in spec["paths"].items():
        for method, operation in item.items():
            if path.startswith("/v1/"):
                assert operation["security"] == [{name: []}], (path, method)
                assert "401" in operation["responses"], (path, method)
            else:
                assert "security" not in operation and "401" not in operation["responses"], (path, method)


def _samples_limit(env: dict[str, str]) -> dict[str, Any]:
    """The schema's samples bounds, and the answers at and past the limit, in a fresh process with ``env``."""
    script = """
import json, warnings
warnings.simplefilter("ignore")
from fastapi.testclient import TestClient
from inertia.api import Settings, create_app
with TestClient(create_app(Settings(compute_processes=1))) as c:
    spec = c.get("/openapi.json").json()
    query = [p for p in spec["paths"]["/v1/analyze/mesh"]["post"]["parameters"] if p["name"] == "samples"][0]
    body = spec["components"]["schemas"]["PointsRequest"]["properties"]["samples"]
    prec = spec["components"]["schemas"]["PrecessionRequest"]["properties"]["samples"]
    limit = query["schema"]["anyOf"][0]["maximum"]
    ask = lambda n: c.post("/v1/precession", json={"principal_moments": [1, 2, 3], "omega": [0, 0, 1],
                                                   "duration": 1.0, "samples": n}).status_code
    print(json.dumps({"query": query["schema"]["anyOf"][0], "points": body["anyOf"][0],
                      "precession": prec["anyOf"][0], "description": query.get("description", ""),
                      "at": ask(limit), "past": ask(limit + 1)}))
"""
    full = {k: v for k, v in os.environ.items() if not k.startswith("INERTIA_")}
    out = subprocess.run(
        [sys.executable, "-c", script], env={**full, **env}, capture_output=True, text=True, timeout=300, check=True
    )
    result: dict[str, Any] = json.loads(out.stdout.strip().splitlines()[-1])
    return result


@pytest.mark.parametrize("env, limit", [({}, 10_000), ({"INERTIA_MAX_SAMPLES": "50"}, 50)])
def test_one_samples_limit_in_schema_validation_and_docs(env: dict[str, str], limit: int) -> None:
    got = _samples_limit(env)
    for where in ("query", "points", "precession"):
        assert (got[where]["minimum"], got[where]["maximum"]) == (2, limit), where
    assert str(limit) in got["description"]
    assert (got["at"], got["past"]) == (200, 422)


def test_a_bad_samples_limit_stops_the_server_with_a_sentence() -> None:
    full = {k: v for k, v in os.environ.items() if not k.startswith("INERTIA_")}
    out = subprocess.run(
        [sys.executable, "-c", "import inertia.api.schemas"],
        capture_output=True,
        text=True,
        env={**full, "INERTIA_MAX_SAMPLES": "lots"},
        timeout=300,
    )
    assert out.returncode != 0 and "INERTIA_MAX_SAMPLES must be a whole number" in out.stderr


def _sections() -> list[type]:
    from inertia import sections

    found = [getattr(sections, name) for name in sections.__all__]
    return [c for c in found if isinstance(c, type) and issubclass(c, sections.Section) and c is not sections.Section]


@pytest.mark.parametrize("section", _sections(), ids=lambda c: c.__name__)
def test_response_schemas_are_the_result_model_sections(spec: dict[str, Any], section: type) -> None:
    """Each section of the result model is a response schema with exactly its keys, in its order, required
    where the dataclass requires them: a field added to a section is in the schema without a second edit."""
    from dataclasses import MISSING, fields

    from inertia.api.schemas import response_model

    schema = spec["components"]["schemas"][response_model(section).__name__]
    keys = [f.metadata.get("key") or f.name for f in fields(section)]
    required = [k for f, k in zip(fields(section), keys, strict=True) if f.default is MISSING and f.default_factory is MISSING]
    assert list(schema["properties"]) == keys
    assert schema.get("required", []) == required
    assert schema["additionalProperties"] is False


def test_closed_sets_and_defaults_in_the_schema_are_the_vocabulary_and_the_options(spec: dict[str, Any]) -> None:
    from inertia.options import DEFAULT_OPTIONS
    from inertia.tolerances import DEFAULT_TOLERANCES
    from inertia.vocabulary import (
        Geometry,
        Isotopes,
        MassUnit,
        Model,
        MotionMethod,
        Regime,
        RotorKind,
        SourceKind,
        UnitsFrom,
        values,
    )

    schemas = spec["components"]["schemas"]
    query = {p["name"]: p["schema"] for p in spec["paths"]["/v1/analyze/mesh"]["post"]["parameters"]}
    body = schemas["PointsRequest"]["properties"]
    for where in (query, body, schemas["PrecessionRequest"]["properties"]):
        assert (where["method"]["enum"], where["method"]["default"]) == (list(values(MotionMethod)), "exact")
        assert where["tolerance"]["default"] == DEFAULT_TOLERANCES.moment_rel == DEFAULT_OPTIONS.tolerance == 1e-6
    assert (query["model"]["enum"], query["model"]["default"]) == (list(values(Model)), "solid")
    assert (query["geometry"]["enum"], query["geometry"]["default"]) == (list(values(Geometry)), "brep")
    assert query["isotopes"]["enum"] == body["isotopes"]["enum"] == list(values(Isotopes))
    assert (body["mass_unit"]["enum"], body["mass_unit"]["default"]) == (list(values(MassUnit)), "kg")
    assert schemas["SourceOut"]["properties"]["kind"]["enum"] == list(values(SourceKind))
    assert schemas["SourceOut"]["properties"]["units_from"]["enum"] == list(values(UnitsFrom))
    assert schemas["ClassificationOut"]["properties"]["kind"]["enum"] == list(values(RotorKind))
    assert schemas["PrecessionOut"]["properties"]["regime"]["enum"] == list(values(Regime))
