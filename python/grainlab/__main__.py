import sys

from grainlab.cli import main

sys.exit(main())
