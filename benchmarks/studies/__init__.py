"""Levers tried on the march and measured, kept so their numbers reproduce."""
