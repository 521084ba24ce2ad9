"""The exception tree of ``ballbot``: one base, input errors also ``ValueError``."""


class BallbotError(Exception):
    """Base of every error ``ballbot`` raises on purpose."""


class ParameterError(BallbotError, ValueError):
    """A parameter is out of range; the message names the field and the bound."""


class ShapeError(BallbotError, ValueError):
    """An array has the wrong shape or dtype; the message names the expected shape."""


class FileError(BallbotError, OSError):
    """A file could not be read, written or parsed; the message names the path."""


class SolverError(BallbotError):
    """A numerical solve failed: no stabilising LQR gain, an optimiser that did not converge."""
