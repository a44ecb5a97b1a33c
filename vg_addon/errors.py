"""The one exception type of the Virtual Goniometer core, and how its messages list things."""

MAX_LISTED = 20
"""How many rows or problems one message names before it says "and N more"."""


def bounded_list(items, *, lines: bool = False, limit: int = MAX_LISTED) -> str:
    """Join ``items`` for a message: inline (``a, b and 3 more``) or as indented lines.

    Parameters
    ----------
    items : iterable of str
    lines : bool, optional
        One item per line, each indented by two spaces (default: comma-separated).
    limit : int, optional
        How many items to show (default :data:`MAX_LISTED`).
    """
    items = [str(item) for item in items]
    hidden = len(items) - limit
    if lines:
        text = "\n".join(f"  {item}" for item in items[:limit])
        return text + (f"\n  ... and {hidden} more" if hidden > 0 else "")
    return ", ".join(items[:limit]) + (f" and {hidden} more" if hidden > 0 else "")


class GoniometerError(ValueError):
    """A measurement or input problem, with a message that says what is wrong and what to do.

    Every error the core raises for bad input is a ``GoniometerError``; the Blender layer shows its
    message to the user as it is, so the message must stand on its own.
    """
