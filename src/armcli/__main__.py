"""`python -m armcli`: the same entry point as the `armcli` console script."""

from armcli.cli import main

main()
