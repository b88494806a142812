import sys

from tabletcad.cli import main

sys.exit(main())
