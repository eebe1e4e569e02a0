"""The robot spec: pydantic models, cross-reference rules, pi expressions, loading.

May import `armcli.io` and below.
"""
