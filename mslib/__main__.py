"""`python -m mslib …` — see mslib/cli.py."""
import sys

from .cli import main

sys.exit(main())
