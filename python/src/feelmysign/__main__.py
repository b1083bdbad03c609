import sys

from feelmysign.cli import main

sys.exit(main())
