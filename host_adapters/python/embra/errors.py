"""C status codes as Python exceptions, each carrying the C library's message.

Every exception is an :class:`EmbraError` (with ``status``, ``status_name`` and ``message``) and
also the built-in exception a Python programmer expects for that kind of failure, so
``except ValueError`` catches a refused argument as it would anywhere else.
"""

from . import _capi


class EmbraError(Exception):
    """A call into libembra failed. ``message`` is embra_last_error_message() of that call."""

    status = _capi.ERROR_INTERNAL

    def __init__(self, message, status=None):
        super().__init__(message)
        if status is not None:
            self.status = status
        self.message = message

    @property
    def status_name(self):
        return _capi.lib.embra_status_name(self.status).decode()


class InvalidArgumentError(EmbraError, ValueError):
    """EMBRA_ERROR_INVALID_ARGUMENT: NULL, out of range, non-finite, wrong count, degenerate."""
    status = _capi.ERROR_INVALID_ARGUMENT


class StaleIdError(EmbraError, LookupError):
    """EMBRA_ERROR_STALE_ID: the id of a destroyed object, or of another world."""
    status = _capi.ERROR_STALE_ID


class BufferTooSmallError(EmbraError, ValueError):
    """EMBRA_ERROR_BUFFER_TOO_SMALL: an output buffer cannot hold the result; nothing written."""
    status = _capi.ERROR_BUFFER_TOO_SMALL


class SchemaError(EmbraError, ValueError):
    """EMBRA_ERROR_SCHEMA: a JSON scene does not match its schema (message starts with the pointer)."""
    status = _capi.ERROR_SCHEMA


class VersionError(EmbraError, RuntimeError):
    """EMBRA_ERROR_VERSION: these bindings (or a def's version) and the library disagree."""
    status = _capi.ERROR_VERSION


class LockedError(EmbraError, RuntimeError):
    """EMBRA_ERROR_LOCKED: the world is in use by a call in progress on another thread; this call
    changed nothing and did not wait. A World's own methods take turns (its lock), so this comes from
    calls made on the same embra_world* outside the World (another binding, raw ctypes calls)."""
    status = _capi.ERROR_LOCKED


class NumericalError(EmbraError, ArithmeticError):
    """EMBRA_ERROR_NUMERICAL: the step went non-finite; the world is as before the step."""
    status = _capi.ERROR_NUMERICAL


class CancelledError(EmbraError, RuntimeError):
    """EMBRA_ERROR_CANCELLED: World.cancel() stopped the step; the world is as before that frame."""
    status = _capi.ERROR_CANCELLED


class InternalError(EmbraError, RuntimeError):
    """EMBRA_ERROR_INTERNAL: a bug in embra, or out of memory."""
    status = _capi.ERROR_INTERNAL


_BY_STATUS = {cls.status: cls for cls in (InvalidArgumentError, StaleIdError, BufferTooSmallError, SchemaError,
                                          VersionError, LockedError, NumericalError, CancelledError,
                                          InternalError)}


def error_for(status, message=None):
    """The exception for a status code, with the calling thread's last C message."""
    if message is None:
        message = _capi.lib.embra_last_error_message().decode("utf-8", "replace")
    cls = _BY_STATUS.get(status)
    if cls is None:
        return EmbraError(f"{message} (unknown status {status})", status)
    return cls(message)


def check(status):
    """Raises the exception for a failed status; returns None for EMBRA_OK."""
    if status != _capi.OK:
        raise error_for(status)
