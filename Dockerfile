# The HTTP service: python slim, runtime dependencies only, non-root, serves on port 8000.
# Dependencies are installed in their own layer from pyproject.toml alone, so a change to the
# sources rebuilds only the last, small layer.
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1

RUN useradd --create-home --uid 10001 inertia
WORKDIR /app

# 1. dependencies, read from pyproject.toml alone (this layer is cached while it is unchanged)
COPY pyproject.toml ./
# (with the vtk extra: .vtk/.vtu files are read by VTK's own readers, which need no graphics libraries)
RUN python -c "import tomllib; p = tomllib.load(open('pyproject.toml', 'rb'))['project']; print('\n'.join(p['dependencies'] + p['optional-dependencies']['vtk']))" \
        > /tmp/requirements.txt \
    && pip install -r /tmp/requirements.txt && rm /tmp/requirements.txt

# 2. the package itself
COPY README.md LICENSE ./
COPY service ./service
RUN pip install --no-deps . && rm -rf /app/service /app/build /app/README.md /app/LICENSE /app/pyproject.toml

USER inertia
EXPOSE 8000
# Compute processes default to the CPUs the container may use (its cgroup quota, e.g. --cpus 2),
# not the host's core count; INERTIA_COMPUTE_PROCESSES overrides.
HEALTHCHECK --interval=30s --timeout=3s --start-period=20s \
    CMD python -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:8000/healthz', timeout=2)"
CMD ["inertia", "serve", "--host", "0.0.0.0", "--port", "8000"]
