import sys

from riprap.cli import main

sys.exit(main())
