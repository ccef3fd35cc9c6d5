"""python -m service -> the CLI."""

from .cli import main

raise SystemExit(main())
