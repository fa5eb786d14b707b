"""``python -m flex``: see :mod:`flex.cli`."""

import sys

from flex.cli import main

sys.exit(main())
