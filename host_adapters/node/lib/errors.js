'use strict';
// C status codes as JS errors, each carrying the C library's message (embra_last_error_message()).
//
// Every error a C call reports is an EmbraError (with `status`, `statusName` and `message`) of the
// subclass for its status, so `catch (e) { if (e instanceof StaleIdError) ... }` works. Arguments
// refused by the adapter before any C call are the usual TypeError and RangeError instead.

const capi = require('./capi');

/** A call into libembra failed. `message` is embra_last_error_message() of that call. */
class EmbraError extends Error {
  constructor(message, status) {
    super(message);
    this.name = new.target.name;
    this.status = status === undefined ? new.target.STATUS : status;
  }

  /** The C constant's name of the status, e.g. "EMBRA_ERROR_STALE_ID". */
  get statusName() {
    return capi.lib.embra_status_name(this.status);
  }
}
EmbraError.STATUS = capi.ERROR_INTERNAL;

/** EMBRA_ERROR_INVALID_ARGUMENT: NULL, out of range, non-finite, wrong count, degenerate. */
class InvalidArgumentError extends EmbraError {}
InvalidArgumentError.STATUS = capi.ERROR_INVALID_ARGUMENT;

/** EMBRA_ERROR_STALE_ID: the id of a destroyed object, or of another world. */
class StaleIdError extends EmbraError {}
StaleIdError.STATUS = capi.ERROR_STALE_ID;

/** EMBRA_ERROR_BUFFER_TOO_SMALL: an output buffer cannot hold the result; nothing written. */
class BufferTooSmallError extends EmbraError {}
BufferTooSmallError.STATUS = capi.ERROR_BUFFER_TOO_SMALL;

/** EMBRA_ERROR_SCHEMA: a JSON scene does not match its schema (message starts with the pointer). */
class SchemaError extends EmbraError {}
SchemaError.STATUS = capi.ERROR_SCHEMA;

/** EMBRA_ERROR_VERSION: these bindings (or a def's version) and the library disagree. */
class VersionError extends EmbraError {}
VersionError.STATUS = capi.ERROR_VERSION;

/**
 * EMBRA_ERROR_LOCKED: the world is in use by a call in progress on another thread (World.stepAsync's
 * worker); this call changed nothing and did not wait.
 */
class LockedError extends EmbraError {}
LockedError.STATUS = capi.ERROR_LOCKED;

/** EMBRA_ERROR_NUMERICAL: the step went non-finite; the world is as before the step. */
class NumericalError extends EmbraError {}
NumericalError.STATUS = capi.ERROR_NUMERICAL;

/** EMBRA_ERROR_CANCELLED: World.cancel() stopped the step; the world is as before that frame. */
class CancelledError extends EmbraError {}
CancelledError.STATUS = capi.ERROR_CANCELLED;

/** EMBRA_ERROR_INTERNAL: a bug in embra, or out of memory. */
class InternalError extends EmbraError {}
InternalError.STATUS = capi.ERROR_INTERNAL;

const BY_STATUS = new Map([InvalidArgumentError, StaleIdError, BufferTooSmallError, SchemaError, VersionError,
  LockedError, NumericalError, CancelledError, InternalError].map((cls) => [cls.STATUS, cls]));

/** The error for a failed status, with the calling thread's last C message unless one is given. */
function errorFor(status, message) {
  const text = message === undefined ? capi.lib.embra_last_error_message() : message;
  const cls = BY_STATUS.get(status);
  if (cls === undefined) return new EmbraError(`${text} (unknown status ${status})`, status);
  return new cls(text);
}

/** Throws the error for a failed status; returns nothing for EMBRA_OK. */
function check(status) {
  if (status !== capi.OK) throw errorFor(status);
}

module.exports = {
  EmbraError, InvalidArgumentError, StaleIdError, BufferTooSmallError, SchemaError, VersionError, LockedError,
  NumericalError, CancelledError, InternalError, errorFor, check,
};
