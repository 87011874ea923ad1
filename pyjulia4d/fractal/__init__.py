"""The registry of algebras, functions and kinds of set (registry.py)."""
