"""Sidebar panels and lists that only draw, and the viewport labels' draw handler."""

from . import labels, lists, panels

classes = (*lists.classes, *panels.classes)
