"""The native module, atmos's errors as exceptions, and one context per thread."""
import threading

try:
    from atmos._native import ffi, lib
except ImportError as e:  # pragma: no cover - the message is the point
    raise ImportError(
        "atmos: the native module is not built. Run `make build` (or `make test`) in the "
        "checkout, which puts it in python/atmos/, or `pip install ./python` against an "
        f"installed atmos ({e})"
    ) from e

STATUS_NAMES = {
    lib.ATMOS_E_INVALID_ARG: "invalid argument",
    lib.ATMOS_E_NOMEM: "out of memory",
    lib.ATMOS_E_IO: "I/O error",
    lib.ATMOS_E_FORMAT: "malformed file",
    lib.ATMOS_E_UNSUPPORTED: "unsupported",
    lib.ATMOS_E_LIMIT: "limit exceeded",
    lib.ATMOS_E_CANCELLED: "cancelled",
}


class AtmosError(RuntimeError):
    """A failed atmos call: ``status`` is atmos's status code (``atmos_status``), ``message``
    the library's own message (naming the file, key or value at fault)."""

    def __init__(self, status: int, message: str):
        self.status = int(status)
        self.message = message
        super().__init__(f"{message} ({STATUS_NAMES.get(self.status, 'error')}, status {self.status})")


_local = threading.local()


def context():
    """This thread's atmos context (created on first use, all cores, the default cache).
    A context is not shared between threads, so several threads may render at once."""
    ctx = getattr(_local, "ctx", None)
    if ctx is None:
        p = ffi.new("atmos_context **")
        st = lib.atmos_context_create(ffi.NULL, p)
        if st != lib.ATMOS_OK:
            raise AtmosError(st, ffi.string(lib.atmos_status_string(st)).decode())
        ctx = ffi.gc(p[0], lib.atmos_context_destroy)
        _local.ctx = ctx
    return ctx


def check(status: int, ctx=None) -> None:
    """Raises AtmosError with the context's message unless status is ATMOS_OK."""
    if status != lib.ATMOS_OK:
        ctx = ctx if ctx is not None else context()
        raise AtmosError(status, ffi.string(lib.atmos_context_error(ctx)).decode(errors="replace"))


def version() -> str:
    """The library's version, "MAJOR.MINOR.PATCH"."""
    return ffi.string(lib.atmos_version()).decode()


class Owned:
    """An object holding one library object in ``_ptr`` (a cffi pointer with its destructor):
    ``close()`` frees it at once, ``with`` closes it at the block's end, and collection
    frees it otherwise."""

    _ptr = None

    def close(self) -> None:
        """Frees the library object now."""
        if self._ptr is not None:
            ffi.release(self._ptr)
            self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
