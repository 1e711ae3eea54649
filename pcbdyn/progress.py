"""A long run's progress: its messages passed on as they come, and the wall seconds of each of its
stages kept, so that its JSON says where the time went (the speed targets of issue 37 are met stage by
stage, not guessed from a total)."""

from __future__ import annotations

import time


class Stages:
    """Called with a message: passes it on to ``say`` (None: nowhere). :meth:`stage` also begins a stage
    whose wall seconds add up under its key until the next one begins (a stage entered twice adds up)."""

    def __init__(self, say=None):
        self._say = say
        self._key, self._t = None, time.perf_counter()
        self._seconds: dict = {}

    def __call__(self, msg: str) -> None:
        if self._say is not None:
            self._say(msg)

    def stage(self, key: str, msg: str) -> None:
        self._lap()
        self._key = key
        self(msg)

    def seconds(self) -> dict:
        """{stage key: wall seconds} so far, in the order the stages began."""
        self._lap()
        return {k: round(v, 3) for k, v in self._seconds.items()}

    def _lap(self) -> None:
        now = time.perf_counter()
        if self._key is not None:
            self._seconds[self._key] = self._seconds.get(self._key, 0.0) + now - self._t
        self._t = now
