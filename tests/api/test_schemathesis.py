"""Property-based run of the service's own OpenAPI schema (schemathesis): no 5xx, every
response conforms to the schema. Bounded in examples and time so it runs in CI under plain pytest.

``positive_data_acceptance`` is left out on purpose: a request can be valid by the schema and
still be refused by the contract (random bytes as an STL file, density and mass together),
with a 4xx in the envelope, which is what the other checks verify. ``negative_data_rejection``
is left out too: it counts a file part "of the wrong JSON type" as invalid, but a file is bytes,
and a batch answers a bad file with an error line and 200 (the contract).
"""

from __future__ import annotations

import os
import warnings
from typing import TYPE_CHECKING

import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis import checks

from inertia.api import Settings, create_app

if TYPE_CHECKING:
    from schemathesis.specs.openapi.schemas import OpenApiCase

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message="Using `httpx` with `starlette.testclient`")
    app = create_app(Settings(compute_processes=2, timeout_s=20))

CHECKS = [
    checks.not_a_server_error,
    checks.status_code_conformance,
    checks.content_type_conformance,
    checks.response_headers_conformance,
    checks.response_schema_conformance,
    checks.unsupported_method,
]

schema = schemathesis.openapi.from_asgi("/openapi.json", app)


# CI runs 25 examples per operation; a deeper local hunt: INERTIA_SCHEMATHESIS_EXAMPLES=500
EXAMPLES = int(os.environ.get("INERTIA_SCHEMATHESIS_EXAMPLES", "25"))


@schema.parametrize()
@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
def test_api_conforms_to_its_schema(case: OpenApiCase) -> None:
    case.call_and_validate(checks=CHECKS)
