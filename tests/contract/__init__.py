"""Black-box tests of the HTTP contract (API.md) and of the CLI.

Only public surfaces are used: the ASGI app through ``fastapi.testclient``
(``inertia.app.app``, or ``inertia.api.create_app()`` after setting the
``INERTIA_*`` environment variables the contract names) and the command line
through ``python -m inertia``.  Every expected value is computed here, from

* closed formulas (box m(b²+c²)/12, parallel-axis theorem, dumbbell
  m1 m2 l²/(m1+m2), isosceles triatomic molecule, Landau & Lifshitz §§33-37),
* exact rational integration of the vertices as written (``fractions``),
  with eigenvalues at 50 digits (``mpmath``),
* an independent high-accuracy integration of Euler's equations and of the
  attitude (``scipy.integrate.solve_ivp``, DOP853, rtol 1e-12),
* the complete elliptic integral K(k) (``scipy.special.ellipk``).

Nothing here imports the code under test except the app factory.
"""
