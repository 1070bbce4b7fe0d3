"""``python -m openmm_symprk.bench`` = ``symprk bench``."""
import sys

from .cli import main

sys.exit(main())
