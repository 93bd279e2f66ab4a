"""``python -m linmstmm`` is the ``linmstmm`` command."""
from linmstmm.cli import main

raise SystemExit(main())
