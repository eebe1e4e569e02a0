"""Spec -> xacro set -> URDFs expanded by the real xacro package, with one XML formatter.

May import `armcli.spec` and below.
"""
