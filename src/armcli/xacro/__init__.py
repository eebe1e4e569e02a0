"""Xacro without running code: the safe expander, expressions, YAML tags, arguments, lines.

Also `--trust-xacro`'s jail and sandbox. May import `armcli.spec` and below (the compiler
expands the spec's own xacro set here).
"""
