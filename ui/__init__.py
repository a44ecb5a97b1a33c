"""Sidebar panels and the measurement list: drawing only."""

from . import lists, panels

classes = (*lists.classes, *panels.classes)
