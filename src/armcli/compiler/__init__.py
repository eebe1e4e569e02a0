"""Spec -> xacro set -> URDFs expanded by armcli's safe xacro evaluator, one XML formatter.

May import `armcli.xacro` and below (never xacro's Python `eval`: real xacro is the tests'
oracle).
"""
