"""Long computations in steps: generators that yield between chunks of work and return a result.

A stepwise computation is a generator that yields ``None`` after each chunk of work (so that a
caller such as Blender's modal operator can update a progress bar or stop) and returns its
result; ``result = yield from work`` runs it inside another, and :func:`finish` runs it to the
end. Stopping early leaves nothing half-changed that anyone else sees: the chunks only fill the
computation's own arrays.
"""

from __future__ import annotations

from collections.abc import Generator

STEP = 1 << 18
"""Default size of a chunk of work: this many vertices, faces or edge entries (a few tens of
milliseconds of NumPy work on today's machines)."""


def finish(steps: Generator):
    """Run a stepwise computation to the end; its result."""
    while True:
        try:
            next(steps)
        except StopIteration as done:
            return done.value
