"""``python -m service ...``, the contract's name of the command: the ``inertia`` CLI."""

from inertia.cli import console_main

raise SystemExit(console_main())
