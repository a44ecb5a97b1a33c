"""The one exception type of the Virtual Goniometer core."""


class GoniometerError(ValueError):
    """A measurement or input problem, with a message that says what is wrong and what to do.

    Every error the core raises for bad input is a ``GoniometerError``; the Blender layer shows its
    message to the user as it is, so the message must stand on its own.
    """
