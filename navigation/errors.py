"""The errors navigation raises; messages are written for the user."""

from __future__ import annotations


class NavigationError(Exception):
    """Base of every navigation error whose message can be shown to the user as it is."""


class LayerConfigError(NavigationError, ValueError):
    """A layer configuration names an unknown type, parameter or input, or has a cycle."""
