"""lumiere's exceptions.

Every error the renderer reports carries the one-line message the ``lumiere`` command prints
(naming the file and line, or the option, that is wrong):

- :class:`LumiereError` (a :class:`ValueError`): a malformed scene, a bad option, an image too
  large for memory...
- :class:`LumiereOSError` (an :class:`OSError` and a :class:`LumiereError`): a file that cannot be
  read or written; ``errno`` and ``filename`` are set.

``except lumiere.LumiereError`` catches both.
"""

__all__ = ["LumiereError", "LumiereOSError"]


class LumiereError(ValueError):
    """A scene, camera or option lumiere cannot render, with the CLI's one-line message."""


class LumiereOSError(OSError, LumiereError):
    """A file lumiere cannot read or write; ``errno`` and ``filename`` say which and why."""

    def __str__(self) -> str:
        # OSError would print "[Errno N] strerror: filename"; keep the CLI's line, which names both.
        return str(self.args[0]) if self.args else ""
