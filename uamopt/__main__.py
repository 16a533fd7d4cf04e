"""``python -m uamopt`` runs the command line."""

import sys

from uamopt.cli import main

sys.exit(main())
