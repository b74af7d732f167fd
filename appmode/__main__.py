import sys

from appmode.cli.main import main

sys.exit(main())
