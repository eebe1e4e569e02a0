"""Safe file input and output: YAML with line numbers, bounded reads, atomic writes.

May import only `armcli.errors` and `armcli.defaults`.
"""
