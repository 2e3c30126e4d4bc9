"""``python -m ipfric_core.cli``: the command line (what ``./ipfric`` runs)."""
import sys

from . import main

sys.exit(main())
