import sys

from appmode.cli.entry import main

sys.exit(main())
