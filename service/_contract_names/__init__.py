"""The package under the name the HTTP contract gives it: ``service``.

The contract (docs/api.md, "Running and configuration") names the ASGI
application ``service.app:app`` and the command ``python -m service serve``.
The package's import name is ``inertia``; this small package is installed as
``service`` beside it, so both names work wherever the distribution is
installed, not only from a checkout's root (where ``service/`` is the source
folder itself).  It only forwards: ``service.app.app`` *is* ``inertia.app.app``.
"""
