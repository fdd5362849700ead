# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
import sys

from .run_study import main

sys.exit(main())
