"""``pmsm-commission`` entry point."""

import sys

from pmsm_commissioning.app.cli.main import main

sys.exit(main())
