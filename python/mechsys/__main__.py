"""``python -m mechsys``: the command line (see :mod:`mechsys.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
