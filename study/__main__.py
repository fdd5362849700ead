import sys

from .run_study import main

sys.exit(main())
