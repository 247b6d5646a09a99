"""``python -m pipeline.cli ARGS``: the ``pinfeed`` command."""
import sys

from pipeline.cli import main

sys.exit(main())
