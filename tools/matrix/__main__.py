"""``python3 -m tools.matrix``: the test matrix (lanes.py); the standard library only, before any venv exists."""

import sys

from .lanes import main

sys.exit(main())
