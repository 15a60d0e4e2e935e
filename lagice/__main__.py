"""``python -m lagice ...``: the ``lagice`` command (:func:`lagice.cli.main`)."""
import sys

from .cli import main

sys.exit(main())
