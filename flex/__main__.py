"""``python -m flex``: see :mod:`flex.cli`."""

import sys

from .cli import main

sys.exit(main())
