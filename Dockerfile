# The HTTP service: python slim, runtime dependencies only, non-root, serves on port 8000.
# Build steps are the README's install steps (pip install .).
FROM python:3.11-slim

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_NO_CACHE_DIR=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1

RUN useradd --create-home --uid 10001 inertia
WORKDIR /app

COPY pyproject.toml README.md ./
COPY service ./service
# the package lands in site-packages; the sources are not needed at run time
RUN pip install . && rm -rf /app/service /app/pyproject.toml /app/README.md /app/build

USER inertia
EXPOSE 8000
HEALTHCHECK --interval=30s --timeout=3s --start-period=20s \
    CMD python -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:8000/healthz', timeout=2)"
CMD ["inertia", "serve", "--host", "0.0.0.0", "--port", "8000"]
