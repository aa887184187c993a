"""`python -m openmotion`: the same command line as the `openmotion` script."""

from .cli import main

raise SystemExit(main())
