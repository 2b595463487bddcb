"""``python -m plateimpact.cli``: the ``plateimpact`` command."""

import sys

from . import main

sys.exit(main())
