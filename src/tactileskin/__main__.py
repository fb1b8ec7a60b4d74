import sys

from tactileskin.cli import main

sys.exit(main())
