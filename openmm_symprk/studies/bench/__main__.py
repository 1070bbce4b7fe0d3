"""``python -m openmm_symprk.studies.bench`` = ``symprk bench``."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
