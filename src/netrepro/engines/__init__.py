"""Shared numerical engines used by several papers."""
