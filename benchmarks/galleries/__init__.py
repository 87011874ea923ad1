"""The gallery sheets README and the docs show."""
