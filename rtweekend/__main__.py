"""`python -m rtweekend` is the `rtweekend` command."""
import sys

from .cli import main

sys.exit(main())
